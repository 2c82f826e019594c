"""Water temperature of the fish tank: night cools it, day warms it."""
import math

import rclpy
from std_msgs.msg import Float32


def main():
    rclpy.init()
    probe = rclpy.create_node('water_probe')
    every = probe.declare_parameter('every', 0.5).value
    mean = probe.declare_parameter('mean_c', 24.0).value
    swing = probe.declare_parameter('swing_c', 2.5).value
    out = probe.create_publisher(Float32, 'tank/water_c', 10)
    clock = {'t': 0.0}

    def sample():
        clock['t'] += every
        out.publish(Float32(data=mean + swing * math.sin(clock['t'] / 8.0)))

    probe.create_timer(every, sample)
    try:
        rclpy.spin(probe)
    finally:
        probe.destroy_node()
        rclpy.try_shutdown()
