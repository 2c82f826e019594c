import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, String


class VentLogic(Node):
    """Opens the roof vent in steps as the air gets warmer (with hysteresis)."""

    STEPS = ('closed', 'quarter', 'half', 'open')

    def __init__(self) -> None:
        super().__init__('vent_logic')
        self.declare_parameters('', [('comfort_c', 22.0), ('step_c', 3.0), ('hysteresis_c', 0.5)])
        self.level = 0
        self.cmd = self.create_publisher(String, 'greenhouse/vent', 10)
        self.create_subscription(Float32, 'greenhouse/temp', self.decide, 10)

    def decide(self, msg: Float32) -> None:
        comfort = self.get_parameter('comfort_c').value
        step = self.get_parameter('step_c').value
        slack = self.get_parameter('hysteresis_c').value
        wanted = int(max(0.0, msg.data - comfort) // step)
        wanted = min(wanted, len(self.STEPS) - 1)
        if wanted > self.level or (wanted < self.level and msg.data < comfort + self.level * step - slack):
            self.level = wanted
        self.cmd.publish(String(data=self.STEPS[self.level]))


def main() -> None:
    rclpy.init()
    rclpy.spin(VentLogic())
