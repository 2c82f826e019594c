"""Grades the smoke into levels; the alarm only clears after `clear_samples` clean readings."""
import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, String

LEVELS = [(0.0, 'normal'), (50.0, 'warning'), (200.0, 'alarm')]


class AlarmPanel(Node):
    def __init__(self):
        super().__init__('alarm_panel')
        self.declare_parameter('warning_ppm', 50.0)
        self.declare_parameter('alarm_ppm', 200.0)
        self.declare_parameter('clear_samples', 3)
        self.clean_in_a_row = 0
        self.level = 'normal'
        self.publisher = self.create_publisher(String, 'alarm_level', 10)
        self.create_subscription(Float32, 'smoke_ppm', self.on_smoke, 10)

    def on_smoke(self, msg):
        if msg.data >= self.get_parameter('alarm_ppm').value:
            new = 'alarm'
        elif msg.data >= self.get_parameter('warning_ppm').value:
            new = 'warning'
        else:
            new = 'normal'
        if new == 'normal' and self.level != 'normal':
            self.clean_in_a_row += 1
            if self.clean_in_a_row < self.get_parameter('clear_samples').value:
                new = self.level
        else:
            self.clean_in_a_row = 0
        if new != self.level:
            self.get_logger().warn(f'smoke level {self.level} -> {new} ({msg.data:.0f} ppm)')
        self.level = new
        self.publisher.publish(String(data=new))


def main(args=None):
    rclpy.init(args=args)
    node = AlarmPanel()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.try_shutdown()
