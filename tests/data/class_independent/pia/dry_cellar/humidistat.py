"""Runs the dehumidifier above `high_rh` until the air is below `low_rh`."""
import rclpy
from std_msgs.msg import Bool, Float32

from dry_cellar.common import ConfiguredNode


class Humidistat(ConfiguredNode):
    DEFAULTS = {'high_rh': 65.0, 'low_rh': 50.0}

    def __init__(self):
        super().__init__('humidistat')
        self.running = False
        self.run_pub = self.create_publisher(Bool, 'dehumidifier/run', 10)
        self.create_subscription(Float32, 'cellar/rh', self.decide, 10)

    def decide(self, msg):
        if msg.data > self.high_rh:
            self.running = True
        if msg.data < self.low_rh:
            self.running = False
        self.run_pub.publish(Bool(data=self.running))


def main():
    rclpy.init()
    rclpy.spin(Humidistat())
