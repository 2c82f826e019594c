import rclpy
from std_msgs.msg import Int32, Float32
from rclpy.node import Node


class Controller(Node):
    def on_count(self, m):
        if m.data >= self.threshold:
            v = 0.0
        else:
            v = self.vmax * (1.0 - m.data / self.threshold)
        out = Float32()
        out.data = float(v)
        self.publisher.publish(out)

    def __init__(self):
        super().__init__('belt_controller')
        self.declare_parameter('full_speed', 0.5)
        self.declare_parameter('slow_at', 8)
        self.vmax = self.get_parameter('full_speed').value
        self.threshold = self.get_parameter('slow_at').value
        self.publisher = self.create_publisher(Float32, '/conveyor/speed', 10)
        self.subscription = self.create_subscription(
            Int32, '/conveyor/boxes', self.on_count, 10)
        self.get_logger().info('Belt controller started')


def main(args=None):
    rclpy.init(args=args)
    controller = Controller()
    rclpy.spin(controller)
    controller.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
