"""Simulated range sensor: publishes a noisy distance reading at a fixed rate."""
import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


class RangeSensor(Node):
    def __init__(self):
        super().__init__('range_sensor')
        self.declare_parameter('publish_rate', 2.0)
        self.declare_parameter('noise_level', 0.0)
        rate = self.get_parameter('publish_rate').value
        self.noise = self.get_parameter('noise_level').value
        self.publisher = self.create_publisher(Float32, 'distance', 10)
        self.timer = self.create_timer(1.0 / rate, self.tick)
        self.phase = 0.0
        self.get_logger().info(f'range sensor publishing at {rate} Hz')

    def tick(self):
        # Walls approach and recede: a slow sweep between 0.5 m and 2.5 m, plus noise.
        self.phase = (self.phase + 0.1) % 2.0
        reading = 0.5 + abs(self.phase - 1.0) * 2.0 + random.uniform(-self.noise, self.noise)
        self.publisher.publish(Float32(data=float(reading)))


def main(args=None):
    rclpy.init(args=args)
    node = RangeSensor()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
