"""Ambient light in lux: dusk and dawn, compressed into a minute."""
import math

import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Illuminance


class LightMeter(Node):
    def __init__(self) -> None:
        super().__init__('light_meter')
        self.day_length = float(self.declare_parameter('day_length_s', 60.0).value)
        self.peak = float(self.declare_parameter('noon_lux', 800.0).value)
        self.started = self.get_clock().now()
        self.out = self.create_publisher(Illuminance, 'ambient_light', 5)
        self.create_timer(0.2, self.sample)

    def sample(self) -> None:
        t = (self.get_clock().now() - self.started).nanoseconds / 1e9
        lux = max(0.0, self.peak * math.sin(2 * math.pi * t / self.day_length))
        reading = Illuminance()
        reading.header.stamp = self.get_clock().now().to_msg()
        reading.header.frame_id = 'window'
        reading.illuminance = lux
        self.out.publish(reading)


def main() -> None:
    rclpy.init()
    rclpy.spin(LightMeter())
