"""turtle_tf2_broadcaster: publish world -> <turtlename> on /tf from turtlesim's pose topic.

robot_lab's stand-in for the tutorial package's node (see __init__.py); written for the kit.
Node name turtle_tf2_frame_publisher; parameter `turtlename` (default 'turtle'); it listens
to /<turtlename>/pose and sends one transform per pose, stamped with the node's clock.
"""

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster
from turtlesim.msg import Pose

from turtle_tf2_py._shared import fill_rotation, spin_until_stopped


class TurtlePoseBroadcaster(Node):
    """Turns each 2-D turtle pose into a 3-D frame under `world`."""

    def __init__(self):
        super().__init__('turtle_tf2_frame_publisher')
        self.turtlename = self.declare_parameter('turtlename', 'turtle').value
        self.broadcaster = TransformBroadcaster(self)
        # depth 1: only the newest pose matters for a frame that is re-sent at turtlesim's rate
        self.pose_sub = self.create_subscription(
            Pose, f'/{self.turtlename}/pose', self.on_pose, 1)

    def on_pose(self, pose):
        frame = TransformStamped()
        frame.header.stamp = self.get_clock().now().to_msg()
        frame.header.frame_id = 'world'
        frame.child_frame_id = self.turtlename
        # a turtle lives in the plane: x, y and a heading about z
        frame.transform.translation.x = pose.x
        frame.transform.translation.y = pose.y
        frame.transform.translation.z = 0.0
        fill_rotation(frame.transform.rotation, 0.0, 0.0, pose.theta)
        self.broadcaster.sendTransform(frame)


def main():
    rclpy.init()
    spin_until_stopped(TurtlePoseBroadcaster())
