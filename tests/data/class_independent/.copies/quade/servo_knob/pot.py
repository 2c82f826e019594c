import math
import rclpy
from std_msgs.msg import Float32


def main():
    rclpy.init()
    node = rclpy.create_node('pot')
    speed = node.declare_parameter('turn_speed', 0.7).value
    pub = node.create_publisher(Float32, 'knob', 1)
    start = node.get_clock().now()

    def read():
        seconds = (node.get_clock().now() - start).nanoseconds / 1e9
        pub.publish(Float32(data=0.5 + 0.5 * math.sin(speed * seconds)))

    node.create_timer(0.1, read)
    rclpy.spin(node)
