import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


def main(args=None):
    rclpy.init(args=args)
    n = DistSensor()
    try:
        rclpy.spin(n)
    except KeyboardInterrupt:
        pass
    finally:
        n.destroy_node()
        rclpy.try_shutdown()


class DistSensor(Node):
    def step(self):
        # moving wall between 0.5 and 2.5 metres
        self.angle = (self.angle + 0.1) % 2.0
        value = 0.5 + abs(self.angle - 1.0) * 2.0 + random.uniform(-self.jitter, self.jitter)
        self.pub_range.publish(Float32(data=float(value)))

    def __init__(self):
        super().__init__('range_sensor')
        self.declare_parameter('publish_rate', 2.0)
        self.declare_parameter('noise_level', 0.0)
        hz = self.get_parameter('publish_rate').value
        self.jitter = self.get_parameter('noise_level').value
        self.pub_range = self.create_publisher(Float32, 'distance', 10)
        self.tmr = self.create_timer(1.0 / hz, self.step)
        self.angle = 0.0
        self.get_logger().info(f'range sensor publishing at {hz} Hz')


if __name__ == '__main__':
    main()
