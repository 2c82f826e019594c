#!/usr/bin/env python3
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class Base(Node):
    def __init__(self):
        super().__init__('base')
        self.subscription = self.create_subscription(Twist, 'cmd_vel', self.listener_callback, 10)

    def listener_callback(self, msg):
        if msg.angular.z:
            self.get_logger().info('Turning at %.2f rad/s' % msg.angular.z)
        else:
            self.get_logger().info('Driving at %.2f m/s' % msg.linear.x)


def main(args=None):
    rclpy.init(args=args)
    base = Base()
    try:
        rclpy.spin(base)
    except KeyboardInterrupt:
        pass
    finally:
        base.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
