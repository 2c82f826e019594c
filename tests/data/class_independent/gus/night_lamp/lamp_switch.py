"""On below `on_below` lux, off above `off_above`: no flicker at dusk."""
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Illuminance
from std_msgs.msg import Bool


class LampSwitch(Node):
    def __init__(self) -> None:
        super().__init__('lamp_switch')
        self.on_below = float(self.declare_parameter('on_below', 200.0).value)
        self.off_above = float(self.declare_parameter('off_above', 260.0).value)
        self.lit = False
        self.switch = self.create_publisher(Bool, 'lamp_on', 5)
        self.create_subscription(Illuminance, 'ambient_light', self.on_light, 5)

    def on_light(self, reading: Illuminance) -> None:
        if self.lit and reading.illuminance > self.off_above:
            self.lit = False
        elif not self.lit and reading.illuminance < self.on_below:
            self.lit = True
        self.switch.publish(Bool(data=self.lit))


def main() -> None:
    rclpy.init()
    rclpy.spin(LampSwitch())
