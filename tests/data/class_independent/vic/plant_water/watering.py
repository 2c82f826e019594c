import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32


class Watering(Node):

    def __init__(self):
        super().__init__('watering')
        self.declare_parameter('dry_below', 40.0)
        self.declare_parameter('litres_per_percent', 0.05)
        self.declare_parameter('max_litres', 1.0)
        self.subscription = self.create_subscription(
            Float32,
            'soil_moisture',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning
        self.publisher_ = self.create_publisher(Float32, 'water_litres', 10)

    def listener_callback(self, msg):
        missing = self.get_parameter('dry_below').value - msg.data
        litres = Float32()
        litres.data = 0.0
        if missing > 0:
            litres.data = min(self.get_parameter('max_litres').value,
                              missing * self.get_parameter('litres_per_percent').value)
        self.publisher_.publish(litres)


def main(args=None):
    rclpy.init(args=args)

    watering = Watering()

    rclpy.spin(watering)

    watering.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
