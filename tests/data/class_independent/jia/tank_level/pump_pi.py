"""PI controller: pump flow from the level error, with anti-windup."""
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64

QOS = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)


class PumpPI(Node):
    def __init__(self):
        super().__init__('pump_pi')
        self.declare_parameters(namespace='pi', parameters=[
            ('target_m', 1.0), ('kp', 0.3), ('ki', 0.02), ('max_flow', 0.2)])
        self.i_term = 0.0
        self.flow = self.create_publisher(Float64, 'pump/flow', QOS)
        self.create_subscription(Float64, 'tank/level', self.on_level, QOS)

    def p(self, name):
        return self.get_parameter('pi.' + name).value

    def on_level(self, msg: Float64):
        err = self.p('target_m') - msg.data
        unclamped = self.p('kp') * err + self.i_term + self.p('ki') * err
        flow = min(max(unclamped, 0.0), self.p('max_flow'))
        if flow == unclamped:  # only integrate while not saturated
            self.i_term += self.p('ki') * err
        self.flow.publish(Float64(data=flow))


def main():
    rclpy.init()
    pi = PumpPI()
    try:
        rclpy.spin(pi)
    except KeyboardInterrupt:
        pass
