"""A pretend laser range finder: the wall drifts closer and further away."""
import math

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64


class RangeFinder(Node):
    """Publishes the distance to the wall, in metres."""

    def __init__(self):
        super().__init__('range_finder')
        hz = self.declare_parameter('rate_hz', 5.0).value
        self.amplitude = self.declare_parameter('amplitude_m', 0.8).value
        self.pub = self.create_publisher(Float64, 'wall/range', 10)
        self.t0 = self.get_clock().now()
        self.create_timer(1.0 / hz, self.measure)

    def measure(self):
        seconds = (self.get_clock().now() - self.t0).nanoseconds * 1e-9
        msg = Float64()
        msg.data = 1.2 + self.amplitude * math.sin(0.5 * seconds)
        self.pub.publish(msg)


def main():
    rclpy.init()
    finder = RangeFinder()
    rclpy.spin(finder)
    finder.destroy_node()
    rclpy.shutdown()
