"""The machine: logs each order, with the running hours it has collected."""
import time

import rclpy
from std_msgs.msg import Bool

from dry_cellar.common import ConfiguredNode


class Dehumidifier(ConfiguredNode):
    DEFAULTS = {'model': 'DH-10'}

    def __init__(self):
        super().__init__('dehumidifier')
        self.since = None
        self.total = 0.0
        self.create_subscription(Bool, 'dehumidifier/run', self.order, 10)

    def order(self, msg):
        now = time.monotonic()
        if msg.data and self.since is None:
            self.since = now
        elif not msg.data and self.since is not None:
            self.total += now - self.since
            self.since = None
        state = 'running' if msg.data else 'idle'
        self.get_logger().info(f'{self.model}: {state}, {self.total:.0f} s run so far')


def main():
    rclpy.init()
    rclpy.spin(Dehumidifier())
