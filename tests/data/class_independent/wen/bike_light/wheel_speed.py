import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32


class WheelSpeed(Node):
    def __init__(self):
        super().__init__('wheel_speed')
        self.declare_parameter('ride', [0.0, 8.0, 15.0, 22.0, 15.0, 8.0])
        self.ride = list(self.get_parameter('ride').value)
        self.n = 0
        self.pub = self.create_publisher(Float32, 'speed_kmh', 10)
        self.create_timer(0.5, self.pedal)

    def pedal(self):
        self.pub.publish(Float32(data=float(self.ride[self.n % len(self.ride)])))
        self.n += 1


def main():
    rclpy.init()
    rclpy.spin(WheelSpeed())
