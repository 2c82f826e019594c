import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32
import random


class SensorNode(Node):
    def __init__(self):
        super().__init__('sensor_node')

        # Declare and get parameters
        self.declare_parameter('sensor_rate', 10)
        self.declare_parameter('noise_level', 0.1)

        rate = self.get_parameter('sensor_rate').value
        self.noise = self.get_parameter('noise_level').value

        # Create publisher
        self.pub = self.create_publisher(Float32, '/sensor/temperature', 10)

        # Create timer (1/rate seconds)
        self.timer = self.create_timer(1.0 / rate, self.publish_sensor)

        self.get_logger().info(f'Sensor node started (rate: {rate} Hz)')

    def publish_sensor(self):
        # Simulate sensor reading (20-25°C with noise)
        value = 22.5 + random.uniform(-self.noise, self.noise)

        msg = Float32()
        msg.data = value
        self.pub.publish(msg)

        self.get_logger().debug(f'Temperature: {value:.2f}°C')


def main(args=None):
    rclpy.init(args=args)
    node = SensorNode()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
