"""fixed_frame_tf2_broadcaster: carrot1, 2 m to turtle1's left, re-sent at 10 Hz on /tf.

robot_lab's stand-in for the tutorial package's node (see __init__.py); written for the kit.
Node name fixed_frame_tf2_broadcaster. The offset never changes, but the frame goes on /tf
(not /tf_static) so that it is stamped now and rides along with the moving turtle1.
"""

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster

from turtle_tf2_py._shared import spin_until_stopped

CARROT_OFFSET = (0.0, 2.0, 0.0)  # metres in turtle1's frame: y is the turtle's left


class FixedCarrot(Node):
    """Publishes turtle1 -> carrot1 every 100 ms."""

    def __init__(self):
        super().__init__('fixed_frame_tf2_broadcaster')
        self.broadcaster = TransformBroadcaster(self)
        self.timer = self.create_timer(0.1, self.on_timer)

    def on_timer(self):
        carrot = TransformStamped()
        carrot.header.stamp = self.get_clock().now().to_msg()
        carrot.header.frame_id = 'turtle1'
        carrot.child_frame_id = 'carrot1'
        offset = carrot.transform.translation
        offset.x, offset.y, offset.z = CARROT_OFFSET
        carrot.transform.rotation.w = 1.0
        self.broadcaster.sendTransform(carrot)


def main():
    rclpy.init()
    spin_until_stopped(FixedCarrot())
