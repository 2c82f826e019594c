import rclpy
from rclpy.node import Node

from std_msgs.msg import String


class DoorMotor(Node):

    def __init__(self):
        super().__init__('door_motor')
        self.subscription = self.create_subscription(
            String,
            'door_command',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning

    def listener_callback(self, msg):
        self.get_logger().info('Door: "%s"' % msg.data)


def main(args=None):
    rclpy.init(args=args)

    door_motor = DoorMotor()

    rclpy.spin(door_motor)

    door_motor.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
