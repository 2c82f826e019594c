"""Counts cars queueing on the side road (a Poisson-ish arrival, a green that drains it)."""
import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import String, UInt16


class QueueCamera(Node):
    def __init__(self):
        super().__init__('queue_camera')
        self.arrival = self.declare_parameter('arrival_probability', 0.4).value
        self.drain = self.declare_parameter('cars_per_green_tick', 2).value
        self.cars = 0
        self.green = False
        self.count_pub = self.create_publisher(UInt16, 'side_road/queue', 10)
        self.create_subscription(String, 'side_road/light', self.see_light, 10)
        self.create_timer(0.5, self.count)

    def see_light(self, light):
        self.green = light.data == 'GREEN'

    def count(self):
        if random.random() < self.arrival:
            self.cars += 1
        if self.green:
            self.cars = max(0, self.cars - self.drain)
        self.count_pub.publish(UInt16(data=self.cars))


def main():
    rclpy.init()
    rclpy.spin(QueueCamera())
    rclpy.shutdown()
