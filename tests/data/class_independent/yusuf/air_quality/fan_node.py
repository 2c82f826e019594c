import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class FanNode(Node):
    def __init__(self):
        super().__init__('fan_node')
        # Subscriber
        self.cmd_sub = self.create_subscription(Twist, '/fan/cmd', self.cmd_callback, 10)
        self.get_logger().info('Fan node started')

    def cmd_callback(self, msg):
        self.get_logger().info(f'Fan rotor: {msg.angular.z:.1f} rad/s')


def main(args=None):
    rclpy.init(args=args)
    node = FanNode()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
