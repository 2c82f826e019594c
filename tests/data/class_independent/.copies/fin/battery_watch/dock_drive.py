import rclpy
from std_msgs.msg import String
from rclpy.node import Node


class Drive(Node):

    def __init__(self):
        super().__init__('dock_drive')
        self.sub = self.create_subscription(String, 'mission_mode', self.on_mode, 10)

    def on_mode(self, m):
        self.get_logger().info('I heard: "%s"' % m.data)


def main(args=None):
    rclpy.init(args=args)
    node = Drive()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
