import rclpy
from std_msgs.msg import Float32
from rclpy.node import Node


class Battery(Node):

    def __init__(self):
        super().__init__('battery_sensor')
        self.declare_parameter('drain_per_tick', 0.5)
        self.level = 100.0
        self.pub = self.create_publisher(Float32, 'battery_percent', 10)
        period = 0.5
        self.tmr = self.create_timer(period, self.on_timer)

    def on_timer(self):
        out = Float32()
        out.data = self.level
        self.pub.publish(out)
        self.get_logger().info('Publishing: "%f"' % out.data)
        self.level -= self.get_parameter('drain_per_tick').value
        if self.level < 0.0:
            self.level = 100.0


def main(args=None):
    rclpy.init(args=args)
    node = Battery()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
