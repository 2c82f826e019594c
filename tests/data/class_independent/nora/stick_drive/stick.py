"""A thumb stick played back from a recorded figure-eight (x: turn, y: throttle)."""
import numpy as np
import rclpy
from geometry_msgs.msg import Vector3
from rclpy.node import Node


class Stick(Node):
    def __init__(self):
        super().__init__('stick')
        self.declare_parameter('samples', 50)
        self.declare_parameter('poll_hz', 5.0)
        n = self.get_parameter('samples').value
        angle = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
        self.path = np.stack([np.sin(2 * angle), np.cos(angle)], axis=1)
        self.k = 0
        self.axes = self.create_publisher(Vector3, 'stick/axes', 10)
        self.create_timer(1.0 / self.get_parameter('poll_hz').value, self.poll)

    def poll(self):
        x, y = self.path[self.k % len(self.path)]
        self.k += 1
        self.axes.publish(Vector3(x=float(x), y=float(y), z=0.0))


def main():
    rclpy.init()
    rclpy.spin(Stick())
