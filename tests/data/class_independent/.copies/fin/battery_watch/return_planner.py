import rclpy
from std_msgs.msg import Float32, String
from rclpy.node import Node


class Planner(Node):

    def __init__(self):
        super().__init__('return_planner')
        self.declare_parameter('low_percent', 30.0)
        self.declare_parameter('critical_percent', 10.0)
        self.pub = self.create_publisher(String, 'mission_mode', 10)
        self.sub = self.create_subscription(Float32, 'battery_percent', self.on_battery, 10)

    def on_battery(self, m):
        lo = self.get_parameter('low_percent').value
        crit = self.get_parameter('critical_percent').value
        out = String()
        if m.data <= crit:
            out.data = 'stop'
        elif m.data <= lo:
            out.data = 'go_home'
        else:
            out.data = 'explore'
        self.pub.publish(out)


def main(args=None):
    rclpy.init(args=args)
    node = Planner()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
