"""Line position sensor (simulated)."""
import math

import rclpy
from std_msgs.msg import Int32


def main():
    rclpy.init()
    n = rclpy.create_node('line_camera')
    pub = n.create_publisher(Int32, 'line_offset', 10)
    dt = n.declare_parameter('period', 0.1).value
    w = n.declare_parameter('image_width', 320).value
    k = [0]

    def capture():
        k[0] += 1
        px = int(w / 3 * math.sin(k[0] / 15) * math.cos(k[0] / 40))
        pub.publish(Int32(data=px))

    n.create_timer(dt, capture)
    try:
        rclpy.spin(n)
    except KeyboardInterrupt:
        pass
    n.destroy_node()
    rclpy.try_shutdown()
