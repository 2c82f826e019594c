"""Motor board stand-in: logs the left/right wheel speeds a differential drive would get."""
import rclpy
from geometry_msgs.msg import Twist


def main():
    rclpy.init()
    node = rclpy.create_node('motors')
    track = node.declare_parameter('track_width', 0.16).value

    def apply(cmd):
        left = cmd.linear.x - cmd.angular.z * track / 2
        right = cmd.linear.x + cmd.angular.z * track / 2
        node.get_logger().info(f'L={left:.3f} R={right:.3f}')

    node.create_subscription(Twist, 'wheel_cmd', apply, 10)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()
