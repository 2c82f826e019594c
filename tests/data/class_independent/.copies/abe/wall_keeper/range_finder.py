"""Simulated lidar distance to a wall that moves back and forth."""
import math

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64


def main():
    rclpy.init()
    lidar = Lidar()
    rclpy.spin(lidar)
    lidar.destroy_node()
    rclpy.shutdown()


class Lidar(Node):
    """Distance in m."""

    def tick(self):
        secs = (self.get_clock().now() - self.start).nanoseconds * 1e-9
        out = Float64()
        out.data = 1.2 + self.amp * math.sin(0.5 * secs)
        self.publisher.publish(out)

    def __init__(self):
        super().__init__('range_finder')
        freq = self.declare_parameter('rate_hz', 5.0).value
        self.amp = self.declare_parameter('amplitude_m', 0.8).value
        self.publisher = self.create_publisher(Float64, 'wall/range', 10)
        self.start = self.get_clock().now()
        self.create_timer(1.0 / freq, self.tick)
