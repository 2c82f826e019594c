import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32


class CountSensor(Node):
    def __init__(self):
        super().__init__('count_sensor')

        # Declare and get parameters
        self.declare_parameter('sensor_rate', 2)
        self.declare_parameter('max_boxes', 12)
        rate = self.get_parameter('sensor_rate').value
        self.max_boxes = self.get_parameter('max_boxes').value

        # Create publisher
        self.pub = self.create_publisher(Int32, '/conveyor/boxes', 10)

        # Create timer (1/rate seconds)
        self.timer = self.create_timer(1.0 / rate, self.publish_count)
        self.boxes = 0
        self.get_logger().info(f'Count sensor started (rate: {rate} Hz)')

    def publish_count(self):
        # Boxes arrive at random, and the packer takes some away
        self.boxes += random.randint(0, 3) - random.randint(0, 2)
        self.boxes = max(0, min(self.max_boxes, self.boxes))
        msg = Int32()
        msg.data = self.boxes
        self.pub.publish(msg)
        self.get_logger().debug(f'Boxes on belt: {self.boxes}')


def main(args=None):
    rclpy.init(args=args)
    node = CountSensor()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
