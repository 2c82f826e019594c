import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


def main(args=None):
    rclpy.init(args=args)
    motors = Motors()
    try:
        rclpy.spin(motors)
    except KeyboardInterrupt:
        pass
    finally:
        motors.destroy_node()
        rclpy.try_shutdown()


class Motors(Node):
    def cmd_cb(self, twist):
        self.get_logger().info(f'{self.label}: drive at {twist.linear.x:+.2f} m/s')

    def __init__(self):
        super().__init__('wheel_actuator')
        self.declare_parameter('motor_name', 'motor')
        self.label = self.get_parameter('motor_name').value
        self.create_subscription(Twist, 'cmd_vel', self.cmd_cb, 10)


if __name__ == '__main__':
    main()
