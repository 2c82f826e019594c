"""Keeps a distance to the wall: speed proportional to the error, capped."""
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Float32


class DistanceController(Node):
    def __init__(self):
        super().__init__('distance_controller')
        self.declare_parameter('target_distance', 1.0)
        self.declare_parameter('gain', 1.0)
        self.declare_parameter('max_speed', 1.0)
        self.cmd_pub = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Float32, 'distance', self.on_distance, 10)

    def on_distance(self, msg):
        target = self.get_parameter('target_distance').value
        gain = self.get_parameter('gain').value
        limit = self.get_parameter('max_speed').value
        speed = max(-limit, min(limit, gain * (msg.data - target)))
        cmd = Twist()
        cmd.linear.x = float(speed)
        self.cmd_pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    node = DistanceController()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
