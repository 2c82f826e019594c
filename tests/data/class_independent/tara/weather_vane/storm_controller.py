import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, String


class StormController(Node):
    def __init__(self):
        super().__init__('storm_controller')

        # Declare parameters
        self.declare_parameter('storm_threshold', 12.0)
        self.declare_parameter('calm_threshold', 8.0)
        self.threshold = self.get_parameter('storm_threshold').value
        self.calm = self.get_parameter('calm_threshold').value
        self.closed = False

        # Subscribers
        self.wind_sub = self.create_subscription(
            Float32, '/weather/wind_speed', self.wind_callback, 10)

        # Publishers
        self.shutter_pub = self.create_publisher(String, '/house/shutters', 10)

        self.get_logger().info('Storm controller started')

    def wind_callback(self, msg):
        if msg.data > self.threshold and not self.closed:
            self.get_logger().warn(f'Wind HIGH: {msg.data:.1f} m/s, closing shutters')
            self.closed = True
        elif msg.data < self.calm and self.closed:
            self.closed = False
        command = String()
        command.data = 'CLOSE' if self.closed else 'OPEN'
        self.shutter_pub.publish(command)


def main(args=None):
    rclpy.init(args=args)
    node = StormController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
