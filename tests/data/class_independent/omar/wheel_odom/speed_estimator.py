"""Ticks -> wheel speed in m/s, from the difference between two samples, smoothed."""
import math

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64, Int64


class SpeedEstimator(Node):
    def __init__(self):
        super().__init__('speed_estimator')
        self.declare_parameter('ticks_per_rev', 360)
        self.declare_parameter('wheel_radius', 0.035)
        self.declare_parameter('smoothing', 0.3)
        self._last = None  # (ticks, time in s)
        self._speed = 0.0
        self.speed_pub = self.create_publisher(Float64, 'left_wheel/speed', 20)
        self.create_subscription(Int64, 'left_wheel/ticks', self.on_ticks, 20)

    @property
    def metres_per_tick(self):
        radius = self.get_parameter('wheel_radius').value
        return 2 * math.pi * radius / self.get_parameter('ticks_per_rev').value

    def on_ticks(self, msg):
        now = self.get_clock().now().nanoseconds * 1e-9
        if self._last is not None and now > self._last[1]:
            raw = (msg.data - self._last[0]) * self.metres_per_tick / (now - self._last[1])
            alpha = self.get_parameter('smoothing').value
            self._speed = alpha * raw + (1 - alpha) * self._speed
            self.speed_pub.publish(Float64(data=self._speed))
        self._last = (msg.data, now)


def main():
    rclpy.init()
    node = SpeedEstimator()
    try:
        rclpy.spin(node)
    finally:
        node.destroy_node()
