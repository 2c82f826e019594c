"""The four rotors: more thrust to climb, less to sink; logged per command."""
import rclpy
from geometry_msgs.msg import Twist

from drone_alt.base import LabNode


class Rotors(LabNode):
    SETTINGS = (('hover_rpm', 5200),)

    def setup(self):
        self.create_subscription(Twist, 'drone/cmd_vel', self.spin_up, 10)

    def spin_up(self, cmd):
        rpm = self.cfg['hover_rpm'] * (1.0 + 0.2 * cmd.linear.z)
        self.get_logger().info(f'rotors {rpm:.0f} rpm (climb {cmd.linear.z:+.2f} m/s)')


def main():
    rclpy.init()
    rclpy.spin(Rotors('rotors'))
