"""dynamic_frame_tf2_broadcaster: carrot1 on a 10 m circle around turtle1, at 10 Hz on /tf.

robot_lab's stand-in for the tutorial package's node (see __init__.py); written for the kit.
Node name dynamic_frame_tf2_broadcaster. The angle is pi times the clock's *whole* seconds,
as in the tutorial's program, so in practice the carrot hops between (0, 10) and (0, -10) in
turtle1's frame once a second: what a Jazzy install shows too.
"""

import math

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster

from turtle_tf2_py._shared import spin_until_stopped

RADIUS = 10.0


class CirclingCarrot(Node):
    """Publishes turtle1 -> carrot1 every 100 ms, placed by the current time."""

    def __init__(self):
        super().__init__('dynamic_frame_tf2_broadcaster')
        self.broadcaster = TransformBroadcaster(self)
        self.timer = self.create_timer(0.1, self.on_timer)

    def on_timer(self):
        now = self.get_clock().now()
        whole_seconds = now.seconds_nanoseconds()[0]
        angle = math.pi * whole_seconds
        carrot = TransformStamped()
        carrot.header.stamp = now.to_msg()
        carrot.header.frame_id = 'turtle1'
        carrot.child_frame_id = 'carrot1'
        carrot.transform.translation.x = RADIUS * math.sin(angle)
        carrot.transform.translation.y = RADIUS * math.cos(angle)
        carrot.transform.rotation.w = 1.0
        self.broadcaster.sendTransform(carrot)


def main():
    rclpy.init()
    spin_until_stopped(CirclingCarrot())
