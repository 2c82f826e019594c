"""Relative humidity in the cellar: damp rises slowly, the dehumidifier pulls it down."""
import rclpy
from std_msgs.msg import Bool, Float32

from dry_cellar.common import ConfiguredNode


class Hygrometer(ConfiguredNode):
    DEFAULTS = {'start_rh': 55.0, 'damp_rate': 0.8, 'dry_rate': 2.0, 'every_s': 0.5}

    def __init__(self):
        super().__init__('hygrometer')
        self.rh = self.start_rh
        self.machine_on = False
        self.rh_pub = self.create_publisher(Float32, 'cellar/rh', 10)
        self.create_subscription(Bool, 'dehumidifier/run', self.machine, 10)
        self.create_timer(self.every_s, self.read)

    def machine(self, msg):
        self.machine_on = msg.data

    def read(self):
        self.rh += -self.dry_rate if self.machine_on else self.damp_rate
        self.rh = min(100.0, max(0.0, self.rh))
        self.rh_pub.publish(Float32(data=self.rh))


def main():
    rclpy.init()
    rclpy.spin(Hygrometer())
