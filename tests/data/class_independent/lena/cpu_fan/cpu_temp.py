#!/usr/bin/env python3
# pretend CPU temperature: goes up under "load", down when idle
import time
import random
import rclpy
from std_msgs.msg import Float32


def main():
    rclpy.init()
    node = rclpy.create_node('cpu_temp')
    node.declare_parameter('publish_every', 0.3)
    node.declare_parameter('idle_temp', 40.0)
    every = node.get_parameter('publish_every').value
    temp = node.get_parameter('idle_temp').value
    pub = node.create_publisher(Float32, 'cpu/temp', 10)
    busy = False
    last = time.time()
    while rclpy.ok():
        rclpy.spin_once(node, timeout_sec=0.05)
        if time.time() - last < every:
            continue
        last = time.time()
        if random.random() < 0.1:
            busy = not busy
        if busy:
            temp = temp + random.uniform(0.5, 2.5)
        else:
            temp = temp - random.uniform(0.5, 2.0)
        temp = min(95.0, max(node.get_parameter('idle_temp').value, temp))
        m = Float32()
        m.data = temp
        pub.publish(m)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
