"""PD on the elbow angle: torque = kp * error - kd * d(angle)/dt."""
import time

import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64


class JointPD(Node):
    def __init__(self):
        super().__init__('joint_pd')
        self.goal = self.declare_parameter('goal_rad', 0.8).value
        self.kp = self.declare_parameter('kp', 2.0).value
        self.kd = self.declare_parameter('kd', 0.3).value
        self.previous = None
        group = MutuallyExclusiveCallbackGroup()
        self.torque_pub = self.create_publisher(Float64, 'elbow/torque', 10)
        self.create_subscription(Float64, 'elbow/angle', self.control, 10,
                                 callback_group=group)

    def control(self, msg):
        now = time.monotonic()
        rate = 0.0
        if self.previous is not None and now > self.previous[1]:
            rate = (msg.data - self.previous[0]) / (now - self.previous[1])
        self.previous = (msg.data, now)
        torque = self.kp * (self.goal - msg.data) - self.kd * rate
        self.torque_pub.publish(Float64(data=torque))


def main():
    rclpy.init()
    node = JointPD()
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    try:
        executor.spin()
    finally:
        executor.shutdown()
        node.destroy_node()
