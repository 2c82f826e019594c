import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, Int32


class BeltController(Node):
    def __init__(self):
        super().__init__('belt_controller')

        # Declare parameters
        self.declare_parameter('full_speed', 0.5)
        self.declare_parameter('slow_at', 8)
        self.full_speed = self.get_parameter('full_speed').value
        self.slow_at = self.get_parameter('slow_at').value

        # Subscribers
        self.count_sub = self.create_subscription(
            Int32, '/conveyor/boxes', self.count_callback, 10)

        # Publishers
        self.speed_pub = self.create_publisher(Float32, '/conveyor/speed', 10)

        self.get_logger().info('Belt controller started')

    def count_callback(self, msg):
        # The fuller the end of the belt, the slower it runs
        if msg.data >= self.slow_at:
            speed = 0.0
        else:
            speed = self.full_speed * (1.0 - msg.data / self.slow_at)
        cmd = Float32()
        cmd.data = float(speed)
        self.speed_pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    node = BeltController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
