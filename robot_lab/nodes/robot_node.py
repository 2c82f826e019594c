"""The seed's robot: logs every status, and the commanded speed whenever it changes."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import String

from robot_lab.nodes.base import declare, run_node

__all__ = ['RobotNode', 'main']


class RobotNode(Node):
    """Subscribes /robot/status and /cmd_vel."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('robot_node', **kwargs)
        declare(self, 'robot_name', 'my_robot', 'Name this robot reports at start-up')
        self.robot_name = str(self.get_parameter('robot_name').value)
        self.status_sub = self.create_subscription(
            String, '/robot/status', self.status_callback, 10
        )
        self.cmd_sub = self.create_subscription(Twist, '/cmd_vel', self.cmd_callback, 10)
        self.speed: float | None = None
        self.get_logger().info(f'Robot node started: {self.robot_name}')

    def status_callback(self, msg: String) -> None:
        self.get_logger().info(f'Status: {msg.data}')

    def cmd_callback(self, msg: Twist) -> None:
        speed = float(msg.linear.x)
        if speed != self.speed:
            self.speed = speed
            self.get_logger().info(f'Commanded speed: {speed:.2f} m/s')


def main(args: Sequence[str] | None = None) -> None:
    run_node(RobotNode, args)


if __name__ == '__main__':
    main()
