import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class VentMotor(Node):
    def __init__(self) -> None:
        super().__init__('vent_motor')
        self.position = 'closed'
        self.create_subscription(String, 'greenhouse/vent', self.move, 10)

    def move(self, msg: String) -> None:
        if msg.data != self.position:
            self.get_logger().info(f'moving vent {self.position} -> {msg.data}')
            self.position = msg.data
        else:
            self.get_logger().info(f'vent stays {self.position}')


def main() -> None:
    rclpy.init()
    rclpy.spin(VentMotor())
