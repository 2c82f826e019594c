import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32


class BatterySensor(Node):

    def __init__(self):
        super().__init__('battery_sensor')
        self.declare_parameter('drain_per_tick', 0.5)
        self.publisher_ = self.create_publisher(Float32, 'battery_percent', 10)
        timer_period = 0.5  # seconds
        self.timer = self.create_timer(timer_period, self.timer_callback)
        self.i = 100.0

    def timer_callback(self):
        msg = Float32()
        msg.data = self.i
        self.publisher_.publish(msg)
        self.get_logger().info('Publishing: "%f"' % msg.data)
        self.i -= self.get_parameter('drain_per_tick').value
        if self.i < 0.0:
            self.i = 100.0  # robot was put on the charger


def main(args=None):
    rclpy.init(args=args)

    battery_sensor = BatterySensor()

    rclpy.spin(battery_sensor)

    # Destroy the node explicitly
    battery_sensor.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
