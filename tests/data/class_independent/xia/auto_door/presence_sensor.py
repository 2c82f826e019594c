import random

import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32


class PresenceSensor(Node):

    def __init__(self):
        super().__init__('presence_sensor')
        self.declare_parameter('walk_speed', 0.3)
        self.publisher_ = self.create_publisher(Float32, 'person_distance', 10)
        timer_period = 0.25  # seconds
        self.timer = self.create_timer(timer_period, self.timer_callback)
        self.distance = 5.0
        self.walking_in = True

    def timer_callback(self):
        step = self.get_parameter('walk_speed').value
        self.distance += -step if self.walking_in else step
        if self.distance < 0.2 or self.distance > 5.0:
            self.walking_in = not self.walking_in
        msg = Float32()
        msg.data = self.distance + random.uniform(-0.02, 0.02)
        self.publisher_.publish(msg)


def main(args=None):
    rclpy.init(args=args)

    presence_sensor = PresenceSensor()

    rclpy.spin(presence_sensor)

    presence_sensor.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
