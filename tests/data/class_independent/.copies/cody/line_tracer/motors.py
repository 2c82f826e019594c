"""Differential drive wheels."""
import rclpy
from geometry_msgs.msg import Twist


def main():
    rclpy.init()
    n = rclpy.create_node('motors')
    width = n.declare_parameter('track_width', 0.16).value

    def on_cmd(t):
        l = t.linear.x - t.angular.z * width / 2
        r = t.linear.x + t.angular.z * width / 2
        n.get_logger().info(f'L={l:.3f} R={r:.3f}')

    n.create_subscription(Twist, 'wheel_cmd', on_cmd, 10)
    try:
        rclpy.spin(n)
    except KeyboardInterrupt:
        pass
    n.destroy_node()
    rclpy.try_shutdown()
