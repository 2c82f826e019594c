"""Motor driver stand-in."""
import rclpy
from rclpy.node import Node
from geometry_msgs.msg import Twist


def main():
    rclpy.init()
    motor = Motor()
    rclpy.spin(motor)
    motor.destroy_node()
    rclpy.shutdown()


class Motor(Node):

    def on_cmd(self, cmd):
        self.n += 1
        way = 'forward' if cmd.linear.x > 0 else 'back' if cmd.linear.x < 0 else 'hold'
        self.get_logger().info(f'#{self.n} {way} {abs(cmd.linear.x):.2f} m/s')

    def __init__(self):
        super().__init__('wheels')
        self.n = 0
        self.create_subscription(Twist, 'cmd_vel', self.on_cmd, 10)
