import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32


class Valve(Node):

    def __init__(self):
        super().__init__('valve')
        self.subscription = self.create_subscription(
            Float32,
            'water_litres',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning

    def listener_callback(self, msg):
        if msg.data > 0.0:
            self.get_logger().info('Valve open: %.2f l' % msg.data)
        else:
            self.get_logger().info('Valve closed')


def main(args=None):
    rclpy.init(args=args)

    valve = Valve()

    rclpy.spin(valve)

    valve.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
