"""turtle_tf2_listener: spawn turtle2 and steer it towards `target_frame` through tf2.

robot_lab's stand-in for the tutorial package's node (see __init__.py); written for the kit.
Node name turtle_tf2_frame_listener; parameter `target_frame` (default 'turtle1'). Once a
second it asks tf2 where the target lies in turtle2's frame and publishes a Twist on
turtle2/cmd_vel: turn rate 1.0 x the bearing, speed 0.5 x the distance.
"""

import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

from turtle_tf2_py._shared import TurtleSpawner, spin_until_stopped

TURN_GAIN = 1.0
SPEED_GAIN = 0.5


class TurtleFollower(Node):
    """A proportional chaser: turtle2 heads for wherever the target frame is now."""

    def __init__(self):
        super().__init__('turtle_tf2_frame_listener')
        self.target_frame = self.declare_parameter('target_frame', 'turtle1').value
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.spawner = TurtleSpawner(self, 'turtle2')
        self.cmd_pub = self.create_publisher(Twist, 'turtle2/cmd_vel', 1)
        self.timer = self.create_timer(1.0, self.on_timer)

    def on_timer(self):
        if not self.spawner.step():
            return
        try:
            # Time() (zero) asks for the latest transform both frames have in common
            seen = self.tf_buffer.lookup_transform('turtle2', self.target_frame, Time())
        except TransformException as ex:
            self.get_logger().info(
                f'Could not transform turtle2 to {self.target_frame}: {ex}')
            return
        offset = seen.transform.translation
        cmd = Twist()
        cmd.angular.z = TURN_GAIN * math.atan2(offset.y, offset.x)
        cmd.linear.x = SPEED_GAIN * math.hypot(offset.x, offset.y)
        self.cmd_pub.publish(cmd)


def main():
    rclpy.init()
    spin_until_stopped(TurtleFollower())
