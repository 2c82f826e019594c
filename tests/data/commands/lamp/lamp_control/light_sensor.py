"""A pretend light meter: dusk and dawn, faster than a real day."""
import math

import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Illuminance


class LightSensor(Node):

    def __init__(self):
        super().__init__('light_sensor')
        rate = self.declare_parameter('rate_hz', 5.0).value
        self.period = self.declare_parameter('day_seconds', 8.0).value
        self.pub = self.create_publisher(Illuminance, 'ambient_light', 10)
        self.t = 0.0
        self.step = 1.0 / rate
        self.create_timer(self.step, self.measure)

    def measure(self):
        self.t += self.step
        msg = Illuminance()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = 'light_meter'
        msg.illuminance = 300.0 + 280.0 * math.sin(2 * math.pi * self.t / self.period)
        msg.variance = 4.0
        self.pub.publish(msg)


def main():
    rclpy.init()
    node = LightSensor()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()
