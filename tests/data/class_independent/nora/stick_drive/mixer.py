"""Stick axes -> Twist: a dead zone around the centre, then scaled and clipped."""
import numpy as np
import rclpy
from geometry_msgs.msg import Twist, Vector3
from rclpy.node import Node


def dead_zone(value, width):
    if abs(value) < width:
        return 0.0
    return float(np.sign(value) * (abs(value) - width) / (1.0 - width))


class Mixer(Node):
    def __init__(self):
        super().__init__('mixer')
        self.declare_parameter('dead_zone', 0.1)
        self.declare_parameter('max_linear', 0.5)
        self.declare_parameter('max_angular', 1.5)
        self.twist_out = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Vector3, 'stick/axes', self.mix, 10)

    def mix(self, axes):
        width = self.get_parameter('dead_zone').value
        limits = np.array([self.get_parameter('max_linear').value,
                           self.get_parameter('max_angular').value])
        wanted = np.array([dead_zone(axes.y, width), -dead_zone(axes.x, width)]) * limits
        linear, angular = np.clip(wanted, -limits, limits)
        cmd = Twist()
        cmd.linear.x, cmd.angular.z = float(linear), float(angular)
        self.twist_out.publish(cmd)


def main():
    rclpy.init()
    rclpy.spin(Mixer())
