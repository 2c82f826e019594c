import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, String
from geometry_msgs.msg import Twist


class ControllerNode(Node):
    def __init__(self):
        super().__init__('controller_node')

        # Declare parameters
        self.declare_parameter('control_rate', 20)
        self.declare_parameter('temp_threshold', 25.0)

        rate = self.get_parameter('control_rate').value
        self.threshold = self.get_parameter('temp_threshold').value

        # Subscribers
        self.temp_sub = self.create_subscription(
            Float32, '/sensor/temperature', self.temp_callback, 10)

        # Publishers
        self.cmd_pub = self.create_publisher(Twist, '/cmd_vel', 10)
        self.status_pub = self.create_publisher(String, '/robot/status', 10)

        # Timer for control loop
        self.timer = self.create_timer(1.0 / rate, self.control_loop)

        self.last_temp = 22.0
        self.get_logger().info('Controller node started')

    def temp_callback(self, msg):
        self.last_temp = msg.data
        if msg.data > self.threshold:
            self.get_logger().warn(f'Temperature HIGH: {msg.data:.2f}°C')

    def control_loop(self):
        # Publish status
        status = String()
        status.data = f'OK (temp: {self.last_temp:.1f}°C)'
        self.status_pub.publish(status)


def main(args=None):
    rclpy.init(args=args)
    node = ControllerNode()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
