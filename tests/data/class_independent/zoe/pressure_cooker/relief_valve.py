"""The valve: logs the opening it was told, as a percentage and a hiss."""
from __future__ import annotations

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64


class ReliefValve(Node):
    def __init__(self) -> None:
        super().__init__('relief_valve')
        self.create_subscription(Float64, 'cooker/valve_opening', self.on_opening, 10)

    def on_opening(self, msg: Float64) -> None:
        hiss = 's' * int(msg.data * 10)
        self.get_logger().info(f'valve {msg.data:4.0%} h{hiss}')


def main() -> None:
    rclpy.init()
    node = ReliefValve()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
