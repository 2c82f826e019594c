"""The wheel motors: receive velocity commands and log each one."""
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class WheelActuator(Node):
    def __init__(self):
        super().__init__('wheel_actuator')
        self.declare_parameter('motor_name', 'motor')
        self.motor = self.get_parameter('motor_name').value
        self.create_subscription(Twist, 'cmd_vel', self.on_command, 10)

    def on_command(self, msg):
        self.get_logger().info(f'{self.motor}: drive at {msg.linear.x:+.2f} m/s')


def main(args=None):
    rclpy.init(args=args)
    node = WheelActuator()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
