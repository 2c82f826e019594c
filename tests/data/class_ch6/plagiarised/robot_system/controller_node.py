import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Float32


def main(args=None):
    rclpy.init(args=args)
    ctl = WallFollower()
    try:
        rclpy.spin(ctl)
    except KeyboardInterrupt:
        pass
    finally:
        ctl.destroy_node()
        rclpy.try_shutdown()


class WallFollower(Node):
    def on_reading(self, m):
        goal = self.get_parameter('target_distance').value
        k = self.get_parameter('gain').value
        vmax = self.get_parameter('max_speed').value
        v = max(-vmax, min(vmax, k * (m.data - goal)))
        out = Twist()
        out.linear.x = float(v)
        self.velocity_publisher.publish(out)

    def __init__(self):
        super().__init__('distance_controller')
        self.declare_parameter('target_distance', 1.0)
        self.declare_parameter('gain', 1.0)
        self.declare_parameter('max_speed', 1.0)
        self.velocity_publisher = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Float32, 'distance', self.on_reading, 10)


if __name__ == '__main__':
    main()
