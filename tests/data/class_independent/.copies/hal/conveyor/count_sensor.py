import rclpy
import random
from std_msgs.msg import Int32
from rclpy.node import Node


class BoxCounter(Node):
    def update(self):
        self.count += random.randint(0, 3) - random.randint(0, 2)
        self.count = max(0, min(self.limit, self.count))
        out = Int32()
        out.data = self.count
        self.publisher.publish(out)
        self.get_logger().debug(f'Boxes on belt: {self.count}')

    def __init__(self):
        super().__init__('count_sensor')
        self.declare_parameter('sensor_rate', 2)
        self.declare_parameter('max_boxes', 12)
        hz = self.get_parameter('sensor_rate').value
        self.limit = self.get_parameter('max_boxes').value
        self.publisher = self.create_publisher(Int32, '/conveyor/boxes', 10)
        self.timer = self.create_timer(1.0 / hz, self.update)
        self.count = 0
        self.get_logger().info(f'Count sensor started (rate: {hz} Hz)')


def main(args=None):
    rclpy.init(args=args)
    counter = BoxCounter()
    rclpy.spin(counter)
    counter.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
