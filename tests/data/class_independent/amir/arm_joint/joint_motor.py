"""Elbow motor driver: one log line per torque command, in N·m."""
import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64


class JointMotor(Node):
    def __init__(self):
        super().__init__('joint_motor')
        self.create_subscription(Float64, 'elbow/torque', self.apply, 10)

    def apply(self, msg):
        direction = 'up' if msg.data > 0 else 'down'
        self.get_logger().info(f'torque {abs(msg.data):.2f} N·m {direction}')


def main():
    rclpy.init()
    node = JointMotor()
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    try:
        executor.spin()
    finally:
        executor.shutdown()
        node.destroy_node()
