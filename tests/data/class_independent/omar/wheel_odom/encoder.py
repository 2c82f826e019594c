"""Quadrature encoder on the left wheel: a running tick count, the wheel speeding up and
slowing down like a robot doing laps."""
import math
from dataclasses import dataclass

import rclpy
from rclpy.node import Node
from std_msgs.msg import Int64


@dataclass
class Wheel:
    ticks_per_rev: int
    ticks: float = 0.0
    t: float = 0.0

    def advance(self, dt: float) -> int:
        self.t += dt
        revs_per_s = 1.5 + math.sin(self.t / 3.0)
        self.ticks += revs_per_s * self.ticks_per_rev * dt
        return int(self.ticks)


class Encoder(Node):
    def __init__(self):
        super().__init__('encoder')
        self.declare_parameter('ticks_per_rev', 360)
        self.declare_parameter('sample_period', 0.1)
        self.wheel = Wheel(self.get_parameter('ticks_per_rev').value)
        self.period = self.get_parameter('sample_period').value
        self.ticks_pub = self.create_publisher(Int64, 'left_wheel/ticks', 20)
        self.create_timer(self.period, self.on_sample)

    def on_sample(self):
        self.ticks_pub.publish(Int64(data=self.wheel.advance(self.period)))


def main():
    rclpy.init()
    node = Encoder()
    try:
        rclpy.spin(node)
    finally:
        node.destroy_node()
