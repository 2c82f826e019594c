"""Switches the lamp on when it gets dark, with hysteresis so it does not flicker."""
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Illuminance
from std_msgs.msg import Bool


class LampController(Node):

    def __init__(self):
        super().__init__('lamp_controller')
        self.on_below = self.declare_parameter('on_below_lux', 200.0).value
        self.off_above = self.declare_parameter('off_above_lux', 250.0).value
        self.lamp_on = False
        self.pub = self.create_publisher(Bool, 'lamp/on', 10)
        self.create_subscription(Illuminance, 'ambient_light', self.on_light, 10)

    def on_light(self, msg):
        if msg.illuminance < self.on_below:
            self.lamp_on = True
        elif msg.illuminance > self.off_above:
            self.lamp_on = False
        self.pub.publish(Bool(data=self.lamp_on))


def main():
    rclpy.init()
    node = LampController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()
