import rclpy
from std_msgs.msg import String


def run():
    rclpy.init()
    node = rclpy.create_node('fan_driver')
    log = node.get_logger()
    node.create_subscription(String, '/fan/speed', lambda m: log.info('fan -> ' + m.data), 5)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    rclpy.try_shutdown()
