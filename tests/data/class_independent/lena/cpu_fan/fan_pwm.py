#!/usr/bin/env python3
# the fan: prints a little bar for each duty command
import rclpy
from std_msgs.msg import UInt8


def main():
    rclpy.init()
    node = rclpy.create_node('fan_pwm')

    def duty(m):
        bar = '#' * (m.data // 10)
        node.get_logger().info('fan %3d%% |%-10s|' % (m.data, bar))

    node.create_subscription(UInt8, 'fan/duty', duty, 10)
    while rclpy.ok():
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
