"""`ros2 run turtlesim draw_square`: reset turtlesim, then drive turtle1 round a 2 m square.

As Jazzy's draw_square: every 16 ms a small state machine (forward, stop, turn, stop)
commands turtle1 from its pose: 1 m/s until 2 m ahead, 0.4 rad/s until a quarter turn,
logging each new goal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_srvs.srv import Empty
from turtlesim.msg import Pose

from robot_lab.nodes.base import run_node
from robot_lab.turtlesim.node import topic_qos
from robot_lab.turtlesim.turtle import CANVAS

__all__ = ['DrawSquare', 'main']

PI = 3.141592  # upstream's own


def _at_reset_pose(pose: Pose) -> bool:
    """Where turtlesim's reset puts turtle1: at rest in the middle, facing east."""
    middle = CANVAS / 2
    return bool(abs(pose.x - middle) < 1e-3 and abs(pose.y - middle) < 1e-3
            and abs(pose.theta) < 1e-3 and pose.linear_velocity == 0.0)


class DrawSquare(Node):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__('draw_square', **kwargs)
        self.twist = self.create_publisher(Twist, 'turtle1/cmd_vel', topic_qos())
        self.create_subscription(Pose, 'turtle1/pose', self.on_pose, topic_qos())
        self.reset = self.create_client(Empty, 'reset')
        self.reset_done: Any = None
        self.pose: Pose | None = None
        self.started_at: Any = None  # when the first pose after the reset came
        self.goal = Pose()
        self.state = 'forward'
        self.started = False
        self.create_timer(0.016, self.on_timer)

    def on_pose(self, pose: Pose) -> None:
        if self.reset_done is None or not self.reset_done.done():
            return
        # A pose published before the reset can still be taken after its answer (CI under
        # load: the square aimed from where a teleport had left the turtle). The reset
        # puts turtle1 at rest in the middle, so the first pose to go by is one there;
        # after half a second any pose goes (someone else may have moved it at once).
        if self.pose is None and self.started_at is None:
            self.started_at = self.get_clock().now()
        if self.pose is None and not _at_reset_pose(pose):
            waited = self.get_clock().now() - self.started_at
            if waited.nanoseconds < 500_000_000:
                return
        self.pose = pose

    def _reached(self) -> bool:
        p, g = self.pose, self.goal
        assert p is not None
        return bool(abs(p.x - g.x) < 0.1 and abs(p.y - g.y) < 0.1 and
                    abs(p.theta - g.theta) < 0.01)

    def _stopped(self) -> bool:
        assert self.pose is not None
        return bool(self.pose.angular_velocity < 0.0001 and self.pose.linear_velocity < 0.0001)

    def _command(self, linear: float, angular: float) -> None:
        twist = Twist()
        twist.linear.x = linear
        twist.angular.z = angular
        self.twist.publish(twist)

    def _new_goal(self, x: float, y: float, theta: float) -> None:
        self.goal = Pose(x=x, y=y, theta=theta)
        self.get_logger().info(
            f'New goal [{self.goal.x:f} {self.goal.y:f}, {self.goal.theta:f}]')

    def _ahead(self) -> None:
        p = self.pose
        assert p is not None
        self._new_goal(math.cos(p.theta) * 2 + p.x, math.sin(p.theta) * 2 + p.y, p.theta)

    def on_timer(self) -> None:
        if self.reset_done is None:
            if self.reset.service_is_ready():  # the square starts from a reset turtlesim
                self.reset_done = self.reset.call_async(Empty.Request())
            return
        if not self.reset_done.done() or self.pose is None:
            return
        if not self.started:
            self.started = True
            self.state = 'forward'
            self._ahead()
        if self.state == 'forward':
            if self._reached():
                self.state = 'stop_forward'
                self._command(0.0, 0.0)
            else:
                self._command(1.0, 0.0)
        elif self.state == 'stop_forward':
            if self._stopped():
                self.get_logger().info('Reached goal')
                self.state = 'turn'
                theta = math.fmod(self.pose.theta + PI / 2.0, 2.0 * PI)
                if theta >= PI:  # into [-pi, pi)
                    theta -= 2.0 * PI
                self._new_goal(self.pose.x, self.pose.y, theta)
            else:
                self._command(0.0, 0.0)
        elif self.state == 'turn':
            if self._reached():
                self.state = 'stop_turn'
                self._command(0.0, 0.0)
            else:
                self._command(0.0, 0.4)
        elif self._stopped():
            self.get_logger().info('Reached goal')
            self.state = 'forward'
            self._ahead()
        else:
            self._command(0.0, 0.0)


def main(args: Sequence[str] | None = None) -> None:
    """The `draw_square` executable."""
    run_node(DrawSquare, args)


if __name__ == '__main__':
    main()
