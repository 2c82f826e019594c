"""Climb rate towards the hold altitude: proportional, clipped to the drone's limits."""
import rclpy
from geometry_msgs.msg import Twist
from std_msgs.msg import Float32

from drone_alt.base import LabNode


class AltitudeHold(LabNode):
    SETTINGS = (('hold_m', 3.0), ('k', 0.8), ('max_climb', 1.0))

    def setup(self):
        self.cmd = self.create_publisher(Twist, 'drone/cmd_vel', 10)
        self.create_subscription(Float32, 'drone/altitude', self.hold, 10)

    def hold(self, altitude):
        climb = self.cfg['k'] * (self.cfg['hold_m'] - altitude.data)
        limit = self.cfg['max_climb']
        out = Twist()
        out.linear.z = max(-limit, min(limit, climb))
        self.cmd.publish(out)


def main():
    rclpy.init()
    rclpy.spin(AltitudeHold('altitude_hold'))
