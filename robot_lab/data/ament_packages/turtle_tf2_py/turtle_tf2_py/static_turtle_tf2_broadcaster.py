"""static_turtle_tf2_broadcaster CHILD X Y Z ROLL PITCH YAW: latch world -> CHILD on /tf_static.

robot_lab's stand-in for the tutorial package's node (see __init__.py); written for the kit.
Node name static_turtle_tf2_broadcaster. The transform is sent once; /tf_static is
transient-local, so listeners that start later still receive it.
"""

import sys

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster

from turtle_tf2_py._shared import fill_rotation, spin_until_stopped

USAGE = ('Invalid number of parameters. Usage: \n'
         '$ ros2 run turtle_tf2_py static_turtle_tf2_broadcaster'
         'child_frame_name x y z roll pitch yaw')


class StaticTurtleFrame(Node):
    """Holds the static broadcaster alive for as long as the frame should exist."""

    def __init__(self, child, xyz, rpy):
        super().__init__('static_turtle_tf2_broadcaster')
        self.static_broadcaster = StaticTransformBroadcaster(self)
        frame = TransformStamped()
        frame.header.stamp = self.get_clock().now().to_msg()
        frame.header.frame_id = 'world'
        frame.child_frame_id = child
        translation = frame.transform.translation
        translation.x, translation.y, translation.z = xyz
        fill_rotation(frame.transform.rotation, *rpy)
        self.static_broadcaster.sendTransform(frame)


def main():
    args = sys.argv[1:]
    logger = rclpy.logging.get_logger('logger')
    # the same refusals (and exit codes) as the tutorial's program
    if len(args) != 7:
        logger.info(USAGE)
        sys.exit(1)
    if args[0] == 'world':
        logger.info('Your static turtle name cannot be "world"')
        sys.exit(2)
    numbers = [float(a) for a in args[1:]]
    rclpy.init()
    spin_until_stopped(StaticTurtleFrame(args[0], numbers[:3], numbers[3:]))
