# robot_controller/robot_controller/controller.py
import rclpy
from rclpy.node import Node
from geometry_msgs.msg import Twist


class RobotController(Node):
    def __init__(self):
        super().__init__('robot_controller')

        # Parameters
        self.declare_parameter('max_speed', 1.0)
        self.declare_parameter('update_rate', 10.0)

        # Publisher
        self.cmd_pub = self.create_publisher(
            Twist, 'cmd_vel', 10
        )

        # Timer
        rate = self.get_parameter('update_rate').value
        self.timer = self.create_timer(1.0/rate, self.control_loop)

        self.get_logger().info('Robot controller started')

    def control_loop(self):
        cmd = Twist()
        cmd.linear.x = 0.5
        cmd.angular.z = 0.1
        self.cmd_pub.publish(cmd)


# Not in Chapter 6: its setup.py names `controller = robot_controller.controller:main`,
# but the chapter's controller.py defines no main(). This is the usual one.
def main(args=None):
    rclpy.init(args=args)
    node = RobotController()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == '__main__':
    main()
