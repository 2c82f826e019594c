import rclpy
from std_msgs.msg import Float64


def main():
    rclpy.init()
    node = rclpy.create_node('servo')

    def move(msg):
        node.get_logger().info(f'-> {msg.data:.1f} deg')

    node.create_subscription(Float64, 'servo_deg', move, 1)
    rclpy.spin(node)
