"""The lamp itself: says when it is told to switch."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool


class Lamp(Node):

    def __init__(self):
        super().__init__('lamp')
        self.create_subscription(Bool, 'lamp/on', self.on_command, 10)

    def on_command(self, msg):
        self.get_logger().info('lamp ON' if msg.data else 'lamp off')


def main():
    rclpy.init()
    node = Lamp()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()
