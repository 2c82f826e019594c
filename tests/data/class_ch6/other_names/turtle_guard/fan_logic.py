import rclpy
from sensor_msgs.msg import Temperature
from std_msgs.msg import String


def run():
    rclpy.init()
    node = rclpy.create_node('fan_logic')
    hot = node.declare_parameter('hot_c', 30.0).value
    warm = node.declare_parameter('warm_c', 25.0).value
    speed_pub = node.create_publisher(String, '/fan/speed', 5)

    def decide(reading):
        if reading.temperature >= hot:
            level = 'HIGH'
        elif reading.temperature >= warm:
            level = 'LOW'
        else:
            level = 'OFF'
        speed_pub.publish(String(data=f'{level} ({reading.temperature:.1f} C)'))

    node.create_subscription(Temperature, '/engine/temperature', decide, 5)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    rclpy.try_shutdown()
