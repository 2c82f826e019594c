"""Barometric altitude of a drone that climbs, hovers and descends, in metres."""
import rclpy
from std_msgs.msg import Float32

from drone_alt.base import LabNode

PROFILE = [0.0, 0.5, 1.5, 3.0, 4.5, 5.0, 5.0, 5.0, 4.0, 2.5, 1.0, 0.2]


class Barometer(LabNode):
    SETTINGS = (('period', 0.3), ('offset_m', 0.0))

    def setup(self):
        self.i = 0
        self.alt = self.create_publisher(Float32, 'drone/altitude', 10)
        self.create_timer(self.cfg['period'], self.measure)

    def measure(self):
        height = PROFILE[self.i % len(PROFILE)] + self.cfg['offset_m']
        self.i += 1
        self.alt.publish(Float32(data=float(height)))


def main():
    rclpy.init()
    rclpy.spin(Barometer('barometer'))
