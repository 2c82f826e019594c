"""Three downward IR sensors (left, centre, right): floor distance in cm. Now and then
one of them sees past the edge of a table."""
import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32MultiArray


class IrArray(Node):
    def __init__(self):
        super().__init__('ir_array')
        self.declare_parameter('floor_cm', 2.5)
        self.declare_parameter('edge_chance', 0.15)
        self.declare_parameter('rate', 10.0)
        self.readings = self.create_publisher(Float32MultiArray, 'ir/floor_cm', 10)
        self.create_timer(1.0 / self.get_parameter('rate').value, self.scan)

    def scan(self):
        floor = self.get_parameter('floor_cm').value
        chance = self.get_parameter('edge_chance').value
        values = [floor + random.gauss(0, 0.1) for _ in range(3)]
        if random.random() < chance:
            values[random.randrange(3)] = 80.0  # nothing under that sensor
        self.readings.publish(Float32MultiArray(data=values))


def main():
    rclpy.init()
    rclpy.spin(IrArray())
