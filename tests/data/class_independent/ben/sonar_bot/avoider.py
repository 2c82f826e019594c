#!/usr/bin/env python3
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from sensor_msgs.msg import Range


class Avoider(Node):
    """Drives on while the way is clear; stops and turns when something is close."""

    def __init__(self):
        super().__init__('avoider')
        self.declare_parameter('safe_distance', 0.8)
        self.declare_parameter('cruise_speed', 0.3)
        self.declare_parameter('turn_speed', 1.0)
        self.publisher_ = self.create_publisher(Twist, 'cmd_vel', 10)
        self.subscription = self.create_subscription(Range, 'sonar/front',
                                                     self.listener_callback, 10)

    def listener_callback(self, msg):
        safe = self.get_parameter('safe_distance').get_parameter_value().double_value
        cmd = Twist()
        if msg.range > safe:
            cmd.linear.x = self.get_parameter('cruise_speed').get_parameter_value().double_value
        else:
            cmd.angular.z = self.get_parameter('turn_speed').get_parameter_value().double_value
        self.publisher_.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    avoider = Avoider()
    try:
        rclpy.spin(avoider)
    except KeyboardInterrupt:
        pass
    finally:
        avoider.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
