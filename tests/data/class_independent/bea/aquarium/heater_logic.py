"""Heater power in watts, proportional below the target, never more than the heater has."""
import rclpy
from std_msgs.msg import Float32, UInt16


def main():
    rclpy.init()
    logic = rclpy.create_node('heater_logic')
    target = logic.declare_parameter('target_c', 25.0).value
    watts_per_c = logic.declare_parameter('watts_per_c', 40.0).value
    rating = logic.declare_parameter('rating_w', 100).value
    power = logic.create_publisher(UInt16, 'tank/heater_w', 10)

    def decide(water):
        wanted = max(0.0, (target - water.data) * watts_per_c)
        power.publish(UInt16(data=int(min(rating, wanted))))

    logic.create_subscription(Float32, 'tank/water_c', decide, 10)
    try:
        rclpy.spin(logic)
    finally:
        logic.destroy_node()
        rclpy.try_shutdown()
