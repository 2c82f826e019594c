"""The heater element: one line per power setting."""
import rclpy
from std_msgs.msg import UInt16


def main():
    rclpy.init()
    heater = rclpy.create_node('heater')
    say = heater.get_logger().info
    heater.create_subscription(UInt16, 'tank/heater_w', lambda w: say(f'heating {w.data} W'), 10)
    try:
        rclpy.spin(heater)
    finally:
        heater.destroy_node()
        rclpy.try_shutdown()
