import rclpy
from std_msgs.msg import Float32
from rclpy.node import Node


class Motor(Node):
    def on_speed(self, m):
        self.get_logger().info(f'Belt speed set to {m.data:.2f} m/s')

    def __init__(self):
        super().__init__('belt_motor')
        self.subscription = self.create_subscription(
            Float32, '/conveyor/speed', self.on_speed, 10)
        self.get_logger().info('Belt motor ready')


def main(args=None):
    rclpy.init(args=args)
    motor = Motor()
    rclpy.spin(motor)
    motor.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
