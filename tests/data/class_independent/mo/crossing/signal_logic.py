"""Side road gets green when enough cars wait, keeps it until the queue is gone."""
from enum import Enum

import rclpy
from rclpy.node import Node
from std_msgs.msg import String, UInt16


class Light(Enum):
    RED = 'RED'
    GREEN = 'GREEN'
    YELLOW = 'YELLOW'


class SignalLogic(Node):
    def __init__(self):
        super().__init__('signal_logic')
        self.enough = self.declare_parameter('green_when_waiting', 4).value
        self.yellow_ticks = self.declare_parameter('yellow_ticks', 2).value
        self.light = Light.RED
        self.ticks_in_yellow = 0
        self.light_pub = self.create_publisher(String, 'side_road/light', 10)
        self.create_subscription(UInt16, 'side_road/queue', self.on_queue, 10)

    def on_queue(self, queue):
        if self.light is Light.RED and queue.data >= self.enough:
            self.light = Light.GREEN
        elif self.light is Light.GREEN and queue.data == 0:
            self.light = Light.YELLOW
            self.ticks_in_yellow = 0
        elif self.light is Light.YELLOW:
            self.ticks_in_yellow += 1
            if self.ticks_in_yellow >= self.yellow_ticks:
                self.light = Light.RED
        self.light_pub.publish(String(data=self.light.value))


def main():
    rclpy.init()
    rclpy.spin(SignalLogic())
    rclpy.shutdown()
