import rclpy
from rclpy.node import Node

from std_msgs.msg import Float32
from std_msgs.msg import String


class ReturnPlanner(Node):

    def __init__(self):
        super().__init__('return_planner')
        self.declare_parameter('low_percent', 30.0)
        self.declare_parameter('critical_percent', 10.0)
        self.subscription = self.create_subscription(
            Float32,
            'battery_percent',
            self.listener_callback,
            10)
        self.subscription  # prevent unused variable warning
        self.publisher_ = self.create_publisher(String, 'mission_mode', 10)

    def listener_callback(self, msg):
        low = self.get_parameter('low_percent').value
        critical = self.get_parameter('critical_percent').value
        mode = String()
        if msg.data <= critical:
            mode.data = 'stop'
        elif msg.data <= low:
            mode.data = 'go_home'
        else:
            mode.data = 'explore'
        self.publisher_.publish(mode)


def main(args=None):
    rclpy.init(args=args)

    return_planner = ReturnPlanner()

    rclpy.spin(return_planner)

    return_planner.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
