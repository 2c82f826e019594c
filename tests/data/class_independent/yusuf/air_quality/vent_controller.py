import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Float32


class VentController(Node):
    def __init__(self):
        super().__init__('vent_controller')
        # Declare parameters
        self.declare_parameter('good_ppm', 800.0)
        self.declare_parameter('bad_ppm', 1400.0)
        self.good = self.get_parameter('good_ppm').value
        self.bad = self.get_parameter('bad_ppm').value
        # Subscribers
        self.co2_sub = self.create_subscription(Float32, '/room/co2', self.co2_callback, 10)
        # Publishers (the fan speed is sent as a Twist, angular.z = rotor speed)
        self.fan_pub = self.create_publisher(Twist, '/fan/cmd', 10)
        self.get_logger().info('Vent controller started')

    def co2_callback(self, msg):
        if msg.data > self.bad:
            self.get_logger().warn(f'CO2 HIGH: {msg.data:.0f} ppm')
        share = (msg.data - self.good) / (self.bad - self.good)
        cmd = Twist()
        cmd.angular.z = 10.0 * min(1.0, max(0.0, share))
        self.fan_pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    node = VentController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
