"""Go forward unless a sensor reads further than `cliff_cm`; then back off and turn away."""
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Float32MultiArray


class CliffGuard(Node):
    def __init__(self):
        super().__init__('cliff_guard')
        self.declare_parameter('cliff_cm', 10.0)
        self.declare_parameter('forward', 0.2)
        self.declare_parameter('escape_turn', 1.2)
        self.cmd = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Float32MultiArray, 'ir/floor_cm', self.check, 10)

    def check(self, msg):
        limit = self.get_parameter('cliff_cm').value
        left, centre, right = [d > limit for d in msg.data[:3]]
        out = Twist()
        if not (left or centre or right):
            out.linear.x = self.get_parameter('forward').value
        else:
            out.linear.x = -0.5 * self.get_parameter('forward').value
            turn = self.get_parameter('escape_turn').value
            out.angular.z = -turn if left else turn
        self.cmd.publish(out)


def main():
    rclpy.init()
    rclpy.spin(CliffGuard())
