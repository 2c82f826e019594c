import random

import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32


class SoilProbe(Node):

    def __init__(self):
        super().__init__('soil_probe')
        self.declare_parameter('dry_per_tick', 1.5)
        self.publisher_ = self.create_publisher(Float32, 'soil_moisture', 10)
        timer_period = 1.0  # seconds
        self.timer = self.create_timer(timer_period, self.timer_callback)
        self.moisture = 70.0

    def timer_callback(self):
        self.moisture -= self.get_parameter('dry_per_tick').value * random.random()
        if self.moisture < 15.0:
            self.moisture = 80.0  # it rained
        msg = Float32()
        msg.data = self.moisture
        self.publisher_.publish(msg)


def main(args=None):
    rclpy.init(args=args)

    soil_probe = SoilProbe()

    rclpy.spin(soil_probe)

    soil_probe.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
