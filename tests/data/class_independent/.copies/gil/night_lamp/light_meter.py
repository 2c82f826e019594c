# light sensor: simulated day/night cycle
import math
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Illuminance


class LuxSensor(Node):
    def measure(self):
        elapsed = (self.get_clock().now() - self.t_start).nanoseconds / 1e9
        value = max(0.0, self.max_lux * math.sin(2 * math.pi * elapsed / self.period))
        m = Illuminance()
        m.header.stamp = self.get_clock().now().to_msg()
        m.header.frame_id = 'window'
        m.illuminance = value
        self.pub.publish(m)

    def __init__(self):
        super().__init__('light_meter')
        self.period = float(self.declare_parameter('day_length_s', 60.0).value)
        self.max_lux = float(self.declare_parameter('noon_lux', 800.0).value)
        self.t_start = self.get_clock().now()
        self.pub = self.create_publisher(Illuminance, 'ambient_light', 5)
        self.create_timer(0.2, self.measure)


def main():
    rclpy.init()
    rclpy.spin(LuxSensor())
