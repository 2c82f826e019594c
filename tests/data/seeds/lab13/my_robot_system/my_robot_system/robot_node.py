import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class RobotNode(Node):
    def __init__(self):
        super().__init__('robot_node')

        self.declare_parameter('robot_name', 'my_robot')
        robot_name = self.get_parameter('robot_name').value

        # Subscriber
        self.status_sub = self.create_subscription(
            String, '/robot/status', self.status_callback, 10)

        self.get_logger().info(f'Robot node started: {robot_name}')

    def status_callback(self, msg):
        self.get_logger().info(f'Status: {msg.data}')


def main(args=None):
    rclpy.init(args=args)
    node = RobotNode()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
