#!/usr/bin/env python3
import random

import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Range


class Sonar(Node):
    def __init__(self):
        super().__init__('sonar')
        self.declare_parameter('frequency', 4.0)
        self.declare_parameter('max_range', 3.0)
        freq = self.get_parameter('frequency').get_parameter_value().double_value
        self.max_range = self.get_parameter('max_range').get_parameter_value().double_value
        self.publisher_ = self.create_publisher(Range, 'sonar/front', 10)
        self.timer = self.create_timer(1.0 / freq, self.timer_callback)
        self.position = self.max_range

    def timer_callback(self):
        # the robot walks towards an obstacle, then it is moved away again
        self.position -= random.uniform(0.05, 0.25)
        if self.position < 0.2:
            self.position = self.max_range
        msg = Range()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = 'sonar_link'
        msg.radiation_type = Range.ULTRASOUND
        msg.field_of_view = 0.5
        msg.min_range = 0.02
        msg.max_range = self.max_range
        msg.range = self.position
        self.publisher_.publish(msg)


def main(args=None):
    rclpy.init(args=args)
    sonar = Sonar()
    try:
        rclpy.spin(sonar)
    except KeyboardInterrupt:
        pass
    finally:
        sonar.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
