import rclpy
from std_msgs.msg import Float32, Float64


def main():
    rclpy.init()
    node = rclpy.create_node('mapper')
    pub = node.create_publisher(Float64, 'servo_deg', 1)
    low = node.declare_parameter('min_deg', -90.0).value
    high = node.declare_parameter('max_deg', 90.0).value

    def convert(msg):
        pub.publish(Float64(data=low + (high - low) * min(1.0, max(0.0, msg.data))))

    node.create_subscription(Float32, 'knob', convert, 1)
    rclpy.spin(node)
