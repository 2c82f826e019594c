"""`ros2 run turtlesim mimic`: one turtle copies another's motion.

As Jazzy's mimic: node /turtle_mimic turns each `input/pose` into a Twist on
`output/cmd_vel` (the pose's linear and angular velocity), so with the launch tutorial's
remaps turtlesim2's turtle drives as turtlesim1's does.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.node import Node
from turtlesim.msg import Pose

from robot_lab.nodes.base import run_node
from robot_lab.turtlesim.node import topic_qos

__all__ = ['MimicNode', 'main']


class MimicNode(Node):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__('turtle_mimic', **kwargs)
        self.twist = self.create_publisher(Twist, 'output/cmd_vel', topic_qos())
        self.create_subscription(Pose, 'input/pose', self.on_pose, topic_qos())

    def on_pose(self, pose: Pose) -> None:
        twist = Twist()
        twist.angular.z = float(pose.angular_velocity)
        twist.linear.x = float(pose.linear_velocity)
        self.twist.publish(twist)


def main(args: Sequence[str] | None = None) -> None:
    """The `mimic` executable."""
    run_node(MimicNode, args)


if __name__ == '__main__':
    main()
