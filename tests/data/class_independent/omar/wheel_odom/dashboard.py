"""The dashboard gauge: km/h, one line per estimate."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64


class Dashboard(Node):
    def __init__(self):
        super().__init__('dashboard')
        self.create_subscription(Float64, 'left_wheel/speed', self.on_speed, 20)

    def on_speed(self, msg):
        self.get_logger().info(f'{msg.data * 3.6:5.2f} km/h')


def main():
    rclpy.init()
    node = Dashboard()
    try:
        rclpy.spin(node)
    finally:
        node.destroy_node()
