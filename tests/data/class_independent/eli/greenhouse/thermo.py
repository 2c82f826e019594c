import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


class Thermo(Node):
    """Greenhouse air temperature: a daily swing sped up, with sensor jitter."""

    def __init__(self) -> None:
        super().__init__('thermo')
        self.declare_parameters('', [('interval', 0.5), ('night_c', 14.0), ('day_c', 31.0)])
        self.night, self.day = (self.get_parameter(n).value for n in ('night_c', 'day_c'))
        self.temp = self.night
        self.rising = True
        self.pub = self.create_publisher(Float32, 'greenhouse/temp', 10)
        self.create_timer(self.get_parameter('interval').value, self.update)

    def update(self) -> None:
        self.temp += 0.7 if self.rising else -0.7
        if self.temp >= self.day or self.temp <= self.night:
            self.rising = not self.rising
        self.pub.publish(Float32(data=self.temp + random.gauss(0.0, 0.2)))


def main() -> None:
    rclpy.init()
    rclpy.spin(Thermo())
