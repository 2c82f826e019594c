"""The drive: it only reports what it was told to do."""
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class Wheels(Node):

    def __init__(self):
        super().__init__('wheels')
        self.count = 0
        self.create_subscription(Twist, 'cmd_vel', self.drive, 10)

    def drive(self, twist):
        self.count += 1
        direction = 'forward' if twist.linear.x > 0 else 'back' if twist.linear.x < 0 else 'hold'
        self.get_logger().info(f'#{self.count} {direction} {abs(twist.linear.x):.2f} m/s')


def main():
    rclpy.init()
    wheels = Wheels()
    rclpy.spin(wheels)
    wheels.destroy_node()
    rclpy.shutdown()
