#!/usr/bin/env python3
# fan curve: 0 % below t_min, 100 % above t_max, a straight line in between
import rclpy
from std_msgs.msg import Float32, UInt8

node = None
pwm_pub = None


def got_temp(m):
    t_min = node.get_parameter('t_min').value
    t_max = node.get_parameter('t_max').value
    floor = node.get_parameter('min_duty').value
    if m.data <= t_min:
        duty = 0
    elif m.data >= t_max:
        duty = 100
    else:
        duty = int(floor + (100 - floor) * (m.data - t_min) / (t_max - t_min))
    out = UInt8()
    out.data = duty
    pwm_pub.publish(out)


def main():
    global node, pwm_pub
    rclpy.init()
    node = rclpy.create_node('fan_curve')
    node.declare_parameter('t_min', 45.0)
    node.declare_parameter('t_max', 80.0)
    node.declare_parameter('min_duty', 20)
    pwm_pub = node.create_publisher(UInt8, 'fan/duty', 10)
    node.create_subscription(Float32, 'cpu/temp', got_temp, 10)
    while rclpy.ok():
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
