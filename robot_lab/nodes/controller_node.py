"""The seed's controller: temperature in, /robot/status and /cmd_vel out.

Better than the seed: status says HIGH above `temp_threshold`, and /cmd_vel really drives
(`max_speed` while OK, 0 while HIGH).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float32, String

from robot_lab.nodes.base import declare, run_node

__all__ = ['ControllerNode', 'main']


class ControllerNode(Node):
    """Runs its control loop at `control_rate` Hz on the latest temperature."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('controller_node', **kwargs)
        declare(self, 'control_rate', 20, 'Control loop rate in Hz', (1, 100))
        declare(self, 'temp_threshold', 25.0, 'Above this temperature (°C) status is HIGH',
                (0.0, 50.0))
        declare(self, 'max_speed', 0.5, 'Forward speed (m/s) commanded while status is OK',
                (0.0, 2.0))
        self.rate = int(self.get_parameter('control_rate').value)
        self.threshold = float(self.get_parameter('temp_threshold').value)
        self.max_speed = float(self.get_parameter('max_speed').value)
        self.temp_sub = self.create_subscription(
            Float32, '/sensor/temperature', self.temp_callback, 10
        )
        self.cmd_pub = self.create_publisher(Twist, '/cmd_vel', 10)
        self.status_pub = self.create_publisher(String, '/robot/status', 10)
        self.timer = self.create_timer(1.0 / self.rate, self.control_loop)
        self.last_temp = 22.0
        self.add_post_set_parameters_callback(self._apply)
        self.get_logger().info('Controller node started')

    def _apply(self, params: list[Parameter]) -> None:
        for param in params:
            if param.name == 'temp_threshold':
                self.threshold = float(param.value)
            elif param.name == 'max_speed':
                self.max_speed = float(param.value)
            elif param.name == 'control_rate' and int(param.value) != self.rate:
                self.rate = int(param.value)
                self.destroy_timer(self.timer)
                self.timer = self.create_timer(1.0 / self.rate, self.control_loop)
                self.get_logger().info(f'Control rate changed to {self.rate} Hz')

    def temp_callback(self, msg: Float32) -> None:
        self.last_temp = msg.data
        if msg.data > self.threshold:
            self.get_logger().warn(f'Temperature HIGH: {msg.data:.2f}°C')

    @property
    def high(self) -> bool:
        return bool(self.last_temp > self.threshold)

    def control_loop(self) -> None:
        status = String()
        state = 'HIGH' if self.high else 'OK'
        status.data = f'{state} (temp: {self.last_temp:.1f}°C)'
        self.status_pub.publish(status)
        cmd = Twist()
        cmd.linear.x = 0.0 if self.high else self.max_speed
        self.cmd_pub.publish(cmd)


def main(args: Sequence[str] | None = None) -> None:
    run_node(ControllerNode, args)


if __name__ == '__main__':
    main()
