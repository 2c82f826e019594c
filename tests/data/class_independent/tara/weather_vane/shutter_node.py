import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class ShutterNode(Node):
    def __init__(self):
        super().__init__('shutter_node')
        self.declare_parameter('house_name', 'my_house')
        house = self.get_parameter('house_name').value

        # Subscriber
        self.cmd_sub = self.create_subscription(
            String, '/house/shutters', self.shutter_callback, 10)

        self.get_logger().info(f'Shutter node started: {house}')

    def shutter_callback(self, msg):
        self.get_logger().info(f'Shutters: {msg.data}')


def main(args=None):
    rclpy.init(args=args)
    node = ShutterNode()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
