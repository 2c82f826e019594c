# actuator
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool


class Relay(Node):
    def callback(self, m):
        s = 'ON' if m.data else 'off'
        if m.data != self.last:
            self.get_logger().info(f'click: lamp {s}')
        else:
            self.get_logger().info(f'lamp still {s}')
        self.last = m.data

    def __init__(self):
        super().__init__('lamp')
        self.last = None
        self.create_subscription(Bool, 'lamp_on', self.callback, 5)


def main():
    rclpy.init()
    rclpy.spin(Relay())
