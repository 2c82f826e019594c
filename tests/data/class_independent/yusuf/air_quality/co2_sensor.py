import random

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


class Co2Sensor(Node):
    def __init__(self):
        super().__init__('co2_sensor')
        # Declare and get parameters
        self.declare_parameter('sensor_rate', 2)
        self.declare_parameter('people', 4)
        rate = self.get_parameter('sensor_rate').value
        self.people = self.get_parameter('people').value
        # Create publisher
        self.pub = self.create_publisher(Float32, '/room/co2', 10)
        # Create timer (1/rate seconds)
        self.timer = self.create_timer(1.0 / rate, self.publish_co2)
        self.ppm = 450.0
        self.get_logger().info(f'CO2 sensor started (rate: {rate} Hz)')

    def publish_co2(self):
        # Every person breathes out some CO2, the window lets some out
        self.ppm += self.people * random.uniform(2.0, 6.0) - (self.ppm - 420.0) * 0.01
        msg = Float32()
        msg.data = self.ppm
        self.pub.publish(msg)
        self.get_logger().debug(f'CO2: {self.ppm:.0f} ppm')


def main(args=None):
    rclpy.init(args=args)
    node = Co2Sensor()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
