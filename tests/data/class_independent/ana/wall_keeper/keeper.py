"""Holds the robot at a set distance from the wall, with a dead band around it."""
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Float64


class Keeper(Node):

    def __init__(self):
        super().__init__('keeper')
        self.setpoint = self.declare_parameter('setpoint_m', 1.0).value
        self.kp = self.declare_parameter('kp', 0.5).value
        self.band = self.declare_parameter('dead_band_m', 0.05).value
        self.out = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Float64, 'wall/range', self.react, 10)

    def react(self, reading):
        error = reading.data - self.setpoint
        twist = Twist()
        if abs(error) > self.band:
            twist.linear.x = self.kp * error
        self.out.publish(twist)
        self.get_logger().debug(f'error {error:.2f} m')


def main():
    rclpy.init()
    keeper = Keeper()
    rclpy.spin(keeper)
    keeper.destroy_node()
    rclpy.shutdown()
