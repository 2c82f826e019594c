"""Tank tracks: show how each Twist is split between the two tracks."""
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class Tracks(Node):
    def __init__(self):
        super().__init__('tracks')
        self.create_subscription(Twist, 'cmd_vel', self.split, 10)

    def split(self, cmd):
        left = cmd.linear.x - 0.2 * cmd.angular.z
        right = cmd.linear.x + 0.2 * cmd.angular.z
        self.get_logger().info(f'tracks  left {left:+.2f}  right {right:+.2f}')


def main():
    rclpy.init()
    rclpy.spin(Tracks())
