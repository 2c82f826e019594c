"""The siren: silent, chirping or howling, and it says which for every order."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

SOUNDS = {'normal': 'silent', 'warning': 'chirp chirp', 'alarm': 'WHOOOOOP WHOOOOOP'}


class Siren(Node):
    def __init__(self):
        super().__init__('siren')
        self.create_subscription(String, 'alarm_level', self.on_level, 10)

    def on_level(self, msg):
        self.get_logger().info(SOUNDS.get(msg.data, f'unknown level {msg.data!r}'))


def main(args=None):
    rclpy.init(args=args)
    node = Siren()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()
