import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class Drive(Node):
    def __init__(self):
        super().__init__('drive')
        self.create_subscription(Twist, 'cmd_vel', self.go, 10)

    def go(self, msg):
        what = 'reverse+turn' if msg.linear.x < 0 else 'forward'
        self.get_logger().info(f'{what}: v={msg.linear.x:.2f} w={msg.angular.z:.2f}')


def main():
    rclpy.init()
    rclpy.spin(Drive())
