import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


class BeltMotor(Node):
    def __init__(self):
        super().__init__('belt_motor')

        # Subscriber
        self.speed_sub = self.create_subscription(
            Float32, '/conveyor/speed', self.speed_callback, 10)

        self.get_logger().info('Belt motor ready')

    def speed_callback(self, msg):
        self.get_logger().info(f'Belt speed set to {msg.data:.2f} m/s')


def main(args=None):
    rclpy.init(args=args)
    node = BeltMotor()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
