"""The seed's sensor: publishes a simulated temperature (22.5 °C ± noise) on /sensor/temperature."""

from __future__ import annotations

import random
from collections.abc import Sequence
from typing import Any

from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float32

from robot_lab.nodes.base import declare, run_node

__all__ = ['BASE_TEMPERATURE', 'SensorNode', 'main']

BASE_TEMPERATURE = 22.5


class SensorNode(Node):
    """Publishes Float32 at `sensor_rate` Hz; `noise_level` is the ± uniform noise."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('sensor_node', **kwargs)
        declare(self, 'sensor_rate', 10, 'Publish rate of /sensor/temperature in Hz', (1, 100))
        declare(self, 'noise_level', 0.1, 'Half-width of the uniform noise in °C', (0.0, 5.0))
        self.rate = int(self.get_parameter('sensor_rate').value)
        self.noise = float(self.get_parameter('noise_level').value)
        self.pub = self.create_publisher(Float32, '/sensor/temperature', 10)
        self.timer = self.create_timer(1.0 / self.rate, self.publish_sensor)
        self.add_post_set_parameters_callback(self._apply)
        self.get_logger().info(f'Sensor node started (rate: {self.rate} Hz)')

    def _apply(self, params: list[Parameter]) -> None:
        """Take new values at once; a new rate means a new timer."""
        for param in params:
            if param.name == 'noise_level':
                self.noise = float(param.value)
            elif param.name == 'sensor_rate' and int(param.value) != self.rate:
                self.rate = int(param.value)
                self.destroy_timer(self.timer)
                self.timer = self.create_timer(1.0 / self.rate, self.publish_sensor)
                self.get_logger().info(f'Sensor rate changed to {self.rate} Hz')

    def publish_sensor(self) -> None:
        value = BASE_TEMPERATURE + random.uniform(-self.noise, self.noise)
        msg = Float32()
        msg.data = value
        self.pub.publish(msg)
        self.get_logger().debug(f'Temperature: {value:.2f}°C')


def main(args: Sequence[str] | None = None) -> None:
    run_node(SensorNode, args)


if __name__ == '__main__':
    main()
