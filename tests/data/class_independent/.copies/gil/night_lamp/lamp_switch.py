# controller: switch the lamp with hysteresis
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool
from sensor_msgs.msg import Illuminance


class Controller(Node):
    def callback(self, m):
        if self.on and m.illuminance > self.upper:
            self.on = False
        elif not self.on and m.illuminance < self.lower:
            self.on = True
        self.pub.publish(Bool(data=self.on))

    def __init__(self):
        super().__init__('lamp_switch')
        self.lower = float(self.declare_parameter('on_below', 200.0).value)
        self.upper = float(self.declare_parameter('off_above', 260.0).value)
        self.on = False
        self.pub = self.create_publisher(Bool, 'lamp_on', 5)
        self.create_subscription(Illuminance, 'ambient_light', self.callback, 5)


def main():
    rclpy.init()
    rclpy.spin(Controller())
