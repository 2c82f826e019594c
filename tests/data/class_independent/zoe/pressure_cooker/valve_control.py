"""How far to open the relief valve: nothing below `crack_kpa`, fully at `full_kpa`."""
from __future__ import annotations

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64


def opening(pressure: float, crack: float, full: float) -> float:
    if pressure <= crack:
        return 0.0
    return min(1.0, (pressure - crack) / (full - crack))


class ValveControl(Node):
    def __init__(self) -> None:
        super().__init__('valve_control')
        self.crack: float = float(self.declare_parameter('crack_kpa', 70.0).value)
        self.full: float = float(self.declare_parameter('full_kpa', 100.0).value)
        self.command = self.create_publisher(Float64, 'cooker/valve_opening', 10)
        self.create_subscription(Float64, 'cooker/pressure_kpa', self.on_pressure, 10)

    def on_pressure(self, msg: Float64) -> None:
        self.command.publish(Float64(data=opening(msg.data, self.crack, self.full)))


def main() -> None:
    rclpy.init()
    node = ValveControl()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
