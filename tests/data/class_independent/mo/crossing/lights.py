"""The lamp head: one log line per command, in the colour's own words."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

SAY = {'RED': 'stop', 'YELLOW': 'prepare to stop', 'GREEN': 'go'}


class Lights(Node):
    def __init__(self):
        super().__init__('lights')
        self.create_subscription(String, 'side_road/light', self.show, 10)

    def show(self, light):
        self.get_logger().info(f'[{light.data:^6}] {SAY.get(light.data, "??")}')


def main():
    rclpy.init()
    rclpy.spin(Lights())
    rclpy.shutdown()
