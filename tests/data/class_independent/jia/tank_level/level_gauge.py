"""Level gauge of a leaking tank that the pump refills (the tank is simulated here)."""
import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64

QOS = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)


class LevelGauge(Node):
    def __init__(self):
        super().__init__('level_gauge')
        self.declare_parameters(namespace='tank', parameters=[
            ('area_m2', 0.5), ('leak_m3s', 0.02), ('dt', 0.1)])
        self.area = self.get_parameter('tank.area_m2').value
        self.leak = self.get_parameter('tank.leak_m3s').value
        self.dt = self.get_parameter('tank.dt').value
        self.level = 0.2
        self.inflow = 0.0
        self.gauge = self.create_publisher(Float64, 'tank/level', QOS)
        self.create_subscription(Float64, 'pump/flow', self.flow_changed, QOS)
        self.create_timer(self.dt, self.integrate)

    def flow_changed(self, msg: Float64):
        self.inflow = msg.data

    def integrate(self):
        self.level = max(0.0, self.level + (self.inflow - self.leak) / self.area * self.dt)
        self.gauge.publish(Float64(data=self.level))


def main():
    rclpy.init()
    gauge = LevelGauge()
    try:
        rclpy.spin(gauge)
    except KeyboardInterrupt:
        pass
