"""Fake line camera: where the black line is, in pixels left (-) or right (+) of centre."""
import math

import rclpy
from std_msgs.msg import Int32


def main():
    rclpy.init()
    node = rclpy.create_node('line_camera')
    width = node.declare_parameter('image_width', 320).value
    period = node.declare_parameter('period', 0.1).value
    topic = node.create_publisher(Int32, 'line_offset', 10)
    frame = [0]

    def grab():
        frame[0] += 1
        # the line wanders like a curvy track
        offset = int(width / 3 * math.sin(frame[0] / 15) * math.cos(frame[0] / 40))
        topic.publish(Int32(data=offset))

    node.create_timer(period, grab)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()
