"""A service server for the course: switch the robot on and off, ask how it is.

Services on std_srvs (which install from PyPI, unlike example_interfaces):
  /enable     std_srvs/srv/SetBool  {data: true|false} -> success, message 'enabled'/...
  /get_state  std_srvs/srv/Trigger  {}                 -> success = enabled, message
Try: `ros2 service call /enable std_srvs/srv/SetBool "{data: true}"`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rclpy.node import Node
from std_srvs.srv import SetBool, Trigger

from robot_lab.nodes.base import declare, run_node

__all__ = ['SwitchNode', 'main']


class SwitchNode(Node):  # type: ignore[misc]
    """Holds one bool (`enabled`), set over /enable and read over /get_state."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('switch', **kwargs)
        declare(self, 'enabled', False, 'Whether the robot starts enabled')
        self.enabled = bool(self.get_parameter('enabled').value)
        self.enable_srv = self.create_service(SetBool, 'enable', self.enable_callback)
        self.state_srv = self.create_service(Trigger, 'get_state', self.state_callback)
        self.get_logger().info(f'Switch node started ({self._state()})')

    def _state(self) -> str:
        return 'enabled' if self.enabled else 'disabled'

    def enable_callback(self, request: SetBool.Request,
                        response: SetBool.Response) -> SetBool.Response:
        changed = bool(request.data) != self.enabled
        self.enabled = bool(request.data)
        response.success = True
        response.message = self._state() if changed else f'already {self._state()}'
        self.get_logger().info(f'Robot {response.message}')
        return response

    def state_callback(self, request: Trigger.Request,
                       response: Trigger.Response) -> Trigger.Response:
        response.success = self.enabled
        response.message = self._state()
        return response


def main(args: Sequence[str] | None = None) -> None:
    run_node(SwitchNode, args)


if __name__ == '__main__':
    main()
