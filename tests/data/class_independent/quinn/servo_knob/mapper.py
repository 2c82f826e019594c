import rclpy
from std_msgs.msg import Float32, Float64


def main():
    rclpy.init()
    n = rclpy.create_node('mapper')
    lo = n.declare_parameter('min_deg', -90.0).value
    hi = n.declare_parameter('max_deg', 90.0).value
    p = n.create_publisher(Float64, 'servo_deg', 1)
    n.create_subscription(Float32, 'knob', lambda m: p.publish(
        Float64(data=lo + (hi - lo) * min(1.0, max(0.0, m.data)))), 1)
    rclpy.spin(n)
