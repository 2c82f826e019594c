"""Cruise control: a speedometer, a PI controller and a throttle, one process.

The car model lives in the speedometer (it integrates the last throttle), so the loop
closes: throttle up -> speed up -> less throttle.
"""
import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float32


class Speedometer(Node):
    def __init__(self):
        super().__init__('speedometer')
        self.dt = 1.0 / self.declare_parameter('sample_hz', 10.0).value
        self.drag = self.declare_parameter('drag', 0.1).value
        self.speed = 0.0
        self.throttle = 0.0
        self.speed_out = self.create_publisher(Float32, 'vehicle/speed', 10)
        self.create_subscription(Float32, 'vehicle/throttle', self.remember, 10)
        self.create_timer(self.dt, self.step)

    def remember(self, msg):
        self.throttle = msg.data

    def step(self):
        self.speed += (self.throttle - self.drag * self.speed) * self.dt
        self.speed_out.publish(Float32(data=self.speed))


class CruiseController(Node):
    def __init__(self):
        super().__init__('cruise_controller')
        self.target = self.declare_parameter('target_speed', 12.0).value
        self.kp = self.declare_parameter('kp', 0.6).value
        self.ki = self.declare_parameter('ki', 0.05).value
        self.integral = 0.0
        self.throttle_out = self.create_publisher(Float32, 'vehicle/throttle', 10)
        self.create_subscription(Float32, 'vehicle/speed', self.control, 10)

    def control(self, msg):
        error = self.target - msg.data
        self.integral = max(-50.0, min(50.0, self.integral + error))
        command = max(0.0, min(5.0, self.kp * error + self.ki * self.integral))
        self.throttle_out.publish(Float32(data=command))


class Throttle(Node):
    def __init__(self):
        super().__init__('throttle')
        self.create_subscription(Float32, 'vehicle/throttle', self.actuate, 10)

    def actuate(self, msg):
        self.get_logger().info('throttle %4.0f %%' % (msg.data / 5.0 * 100))


def main():
    rclpy.init()
    executor = MultiThreadedExecutor()
    nodes = [Speedometer(), CruiseController(), Throttle()]
    for each in nodes:
        executor.add_node(each)
    try:
        executor.spin()
    except KeyboardInterrupt:
        pass
    finally:
        for each in nodes:
            each.destroy_node()
        rclpy.try_shutdown()
