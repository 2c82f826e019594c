"""P steering on the line offset."""
import rclpy
from std_msgs.msg import Int32
from geometry_msgs.msg import Twist


def main():
    rclpy.init()
    n = rclpy.create_node('steering')
    pub = n.create_publisher(Twist, 'wheel_cmd', 10)
    vmax = n.declare_parameter('top_speed', 0.4).value
    gain = n.declare_parameter('k_turn', 0.004).value

    def on_offset(m):
        off = m.data
        t = Twist()
        t.linear.x = vmax / (1.0 + abs(off) / 50.0)
        t.angular.z = -gain * off
        pub.publish(t)

    n.create_subscription(Int32, 'line_offset', on_offset, 10)
    try:
        rclpy.spin(n)
    except KeyboardInterrupt:
        pass
    n.destroy_node()
    rclpy.try_shutdown()
