"""Publishes the cooker's pressure; the cooker heats steadily and never sees the valve
(the valve command is for the relief valve alone), so the reading ramps and wraps."""
from __future__ import annotations

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64

from pressure_cooker.model import Cooker


class Manometer(Node):
    def __init__(self) -> None:
        super().__init__('manometer')
        self.cooker = Cooker(
            heat_kpa_per_s=float(self.declare_parameter('heat_kpa_per_s', 8.0).value),
            vent_kpa_per_s=0.0)
        self.dt: float = float(self.declare_parameter('dt', 0.2).value)
        self.wrap_at: float = float(self.declare_parameter('wrap_kpa', 120.0).value)
        self.out = self.create_publisher(Float64, 'cooker/pressure_kpa', 10)
        self.create_timer(self.dt, self.read)

    def read(self) -> None:
        pressure = self.cooker.step(self.dt, valve_open=0.0)
        if pressure > self.wrap_at:  # the lid was opened: start over
            self.cooker.pressure = 0.0
        self.out.publish(Float64(data=pressure))


def main() -> None:
    rclpy.init()
    node = Manometer()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
