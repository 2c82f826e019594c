"""The relay: says when it clicks, and that it is still in the same state otherwise."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool


class Lamp(Node):
    def __init__(self) -> None:
        super().__init__('lamp')
        self.state: bool | None = None
        self.create_subscription(Bool, 'lamp_on', self.relay, 5)

    def relay(self, cmd: Bool) -> None:
        word = 'ON' if cmd.data else 'off'
        if cmd.data != self.state:
            self.get_logger().info(f'click: lamp {word}')
        else:
            self.get_logger().info(f'lamp still {word}')
        self.state = cmd.data


def main() -> None:
    rclpy.init()
    rclpy.spin(Lamp())
