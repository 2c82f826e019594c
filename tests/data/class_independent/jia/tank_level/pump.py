"""The pump: logs each flow command in litres per second."""
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64

QOS = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)


class Pump(Node):
    def __init__(self):
        super().__init__('pump')
        self.create_subscription(Float64, 'pump/flow', self.run, QOS)

    def run(self, msg: Float64):
        self.get_logger().info(f'pump {msg.data * 1000:6.1f} l/s')


def main():
    rclpy.init()
    pump = Pump()
    try:
        rclpy.spin(pump)
    except KeyboardInterrupt:
        pass
