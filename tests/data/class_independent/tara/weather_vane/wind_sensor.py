import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


class WindSensor(Node):
    def __init__(self):
        super().__init__('wind_sensor')

        # Declare and get parameters
        self.declare_parameter('sensor_rate', 5)
        self.declare_parameter('gust_level', 4.0)
        rate = self.get_parameter('sensor_rate').value
        self.gust = self.get_parameter('gust_level').value

        # Create publisher
        self.pub = self.create_publisher(Float32, '/weather/wind_speed', 10)

        # Create timer (1/rate seconds)
        self.timer = self.create_timer(1.0 / rate, self.publish_wind)
        self.base = 6.0
        self.get_logger().info(f'Wind sensor started (rate: {rate} Hz)')

    def publish_wind(self):
        # Simulate the wind (slowly changing base plus gusts)
        self.base = max(0.0, self.base + random.uniform(-0.5, 0.5))
        value = self.base + random.uniform(0.0, self.gust)
        msg = Float32()
        msg.data = value
        self.pub.publish(msg)
        self.get_logger().debug(f'Wind: {value:.1f} m/s')


def main(args=None):
    rclpy.init(args=args)
    node = WindSensor()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
