import math

import rclpy
from sensor_msgs.msg import Temperature


def run():
    rclpy.init()
    node = rclpy.create_node('thermometer')
    period = node.declare_parameter('period_s', 1.0).value
    base = node.declare_parameter('ambient_c', 20.0).value
    out = node.create_publisher(Temperature, '/engine/temperature', 5)
    state = {'t': 0}

    def sample():
        state['t'] += 1
        reading = Temperature()
        reading.header.stamp = node.get_clock().now().to_msg()
        reading.header.frame_id = 'engine'
        reading.temperature = base + 15.0 * math.sin(state['t'] / 7.0)
        reading.variance = 0.01
        out.publish(reading)

    node.create_timer(period, sample)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    rclpy.try_shutdown()
