"""Smoke density in ppm: clean air, then someone burns toast, then it clears."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32

TOAST = [5, 5, 6, 5, 40, 120, 260, 340, 300, 180, 90, 40, 15, 8, 5, 5]


class SmokeDetector(Node):
    def __init__(self):
        super().__init__('smoke_detector')
        self.declare_parameter('sample_seconds', 0.5)
        self.declare_parameter('scale', 1.0)
        self.index = 0
        self.publisher = self.create_publisher(Float32, 'smoke_ppm', 10)
        self.create_timer(self.get_parameter('sample_seconds').value, self.sample)

    def sample(self):
        ppm = TOAST[self.index] * self.get_parameter('scale').value
        self.index = (self.index + 1) % len(TOAST)
        self.publisher.publish(Float32(data=float(ppm)))


def main(args=None):
    rclpy.init(args=args)
    node = SmokeDetector()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()
