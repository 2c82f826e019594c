import rclpy
from rclpy.node import Node

from std_msgs.msg import String


class DockDrive(Node):

    def __init__(self):
        super().__init__('dock_drive')
        self.subscription = self.create_subscription(
            String,
            'mission_mode',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning

    def listener_callback(self, msg):
        self.get_logger().info('I heard: "%s"' % msg.data)


def main(args=None):
    rclpy.init(args=args)

    dock_drive = DockDrive()

    rclpy.spin(dock_drive)

    dock_drive.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
