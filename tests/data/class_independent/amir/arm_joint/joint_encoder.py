"""Absolute encoder on the elbow joint. The arm is moved by hand in a slow square wave."""
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64


class JointEncoder(Node):
    def __init__(self):
        super().__init__('joint_encoder')
        self.low = self.declare_parameter('low_rad', 0.2).value
        self.high = self.declare_parameter('high_rad', 1.4).value
        self.hold = self.declare_parameter('hold_samples', 15).value
        self.samples = 0
        group = ReentrantCallbackGroup()
        self.angle_pub = self.create_publisher(Float64, 'elbow/angle', 10)
        self.create_timer(0.1, self.sample, callback_group=group)

    def sample(self):
        self.samples += 1
        up = (self.samples // self.hold) % 2 == 1
        self.angle_pub.publish(Float64(data=self.high if up else self.low))


def main():
    rclpy.init()
    node = JointEncoder()
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    try:
        executor.spin()
    finally:
        executor.shutdown()
        node.destroy_node()
