import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32


class Led(Node):
    def __init__(self):
        super().__init__('led')
        self.create_subscription(Int32, 'blinks_per_s', self.show, 10)

    def show(self, msg):
        self.get_logger().info('steady' if msg.data == 0 else f'blink x{msg.data}/s')


def main():
    rclpy.init()
    rclpy.spin(Led())
