import math, rclpy
from std_msgs.msg import Float32


def main():
    rclpy.init()
    n = rclpy.create_node('pot')
    p = n.create_publisher(Float32, 'knob', 1)
    w = n.declare_parameter('turn_speed', 0.7).value
    t0 = n.get_clock().now()
    n.create_timer(0.1, lambda: p.publish(Float32(data=0.5 + 0.5 * math.sin(
        w * (n.get_clock().now() - t0).nanoseconds / 1e9))))
    rclpy.spin(n)
