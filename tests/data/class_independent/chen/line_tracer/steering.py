"""Steer towards the line: turn rate proportional to the offset, slower in curves."""
import rclpy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32


def main():
    rclpy.init()
    node = rclpy.create_node('steering')
    k_turn = node.declare_parameter('k_turn', 0.004).value
    top_speed = node.declare_parameter('top_speed', 0.4).value
    wheel_cmd = node.create_publisher(Twist, 'wheel_cmd', 10)

    def follow(offset_msg):
        pixels = offset_msg.data
        out = Twist()
        out.angular.z = -k_turn * pixels
        out.linear.x = top_speed / (1.0 + abs(pixels) / 50.0)
        wheel_cmd.publish(out)

    node.create_subscription(Int32, 'line_offset', follow, 10)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()
