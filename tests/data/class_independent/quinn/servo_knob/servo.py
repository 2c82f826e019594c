import rclpy
from std_msgs.msg import Float64


def main():
    rclpy.init()
    n = rclpy.create_node('servo')
    log = n.get_logger()
    n.create_subscription(Float64, 'servo_deg', lambda m: log.info(f'-> {m.data:.1f} deg'), 1)
    rclpy.spin(n)
