"""Wall following controller (P control, with a band where it does nothing)."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float64
from geometry_msgs.msg import Twist


def main():
    rclpy.init()
    ctrl = WallController()
    rclpy.spin(ctrl)
    ctrl.destroy_node()
    rclpy.shutdown()


class WallController(Node):

    def on_range(self, meas):
        err = meas.data - self.target
        cmd = Twist()
        if abs(err) > self.deadband:
            cmd.linear.x = self.gain * err
        self.pub.publish(cmd)
        self.get_logger().debug(f'err {err:.2f} m')

    def __init__(self):
        super().__init__('keeper')
        self.target = self.declare_parameter('setpoint_m', 1.0).value
        self.gain = self.declare_parameter('kp', 0.5).value
        self.deadband = self.declare_parameter('dead_band_m', 0.05).value
        self.pub = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Float64, 'wall/range', self.on_range, 10)
