import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, Int32


class BlinkRate(Node):
    """Standing still: steady light (0 blinks); riding: faster blinks the faster I go."""

    def __init__(self):
        super().__init__('blink_rate')
        self.declare_parameter('moving_above', 2.0)
        self.declare_parameter('blinks_per_kmh', 0.2)
        self.declare_parameter('max_blinks', 5)
        self.pub = self.create_publisher(Int32, 'blinks_per_s', 10)
        self.create_subscription(Float32, 'speed_kmh', self.speed, 10)

    def speed(self, msg):
        g = lambda name: self.get_parameter(name).value  # noqa: E731
        blinks = 0
        if msg.data > g('moving_above'):
            blinks = min(g('max_blinks'), 1 + int(msg.data * g('blinks_per_kmh')))
        self.pub.publish(Int32(data=blinks))


def main():
    rclpy.init()
    rclpy.spin(BlinkRate())
