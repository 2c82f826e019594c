"""A service server for the course: switch the robot on and off, ask how it is.

Services on std_srvs (which install from PyPI, unlike example_interfaces):
  /enable     std_srvs/srv/SetBool  {data: true|false} -> success, message 'enabled'/...
  /get_state  std_srvs/srv/Trigger  {}                 -> success = enabled, message
Try: `ros2 service call /enable std_srvs/srv/SetBool "{data: true}"`.

Like demo_nodes_cpp's introspection_service (the services tutorial), the parameter
`service_configure_introspection` (disabled|metadata|contents) turns on service
introspection, so `ros2 service echo /enable` shows each request and response.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rclpy.node import Node
from std_srvs.srv import SetBool, Trigger

from robot_lab.nodes.base import declare, run_node

__all__ = ['SwitchNode', 'main']


class SwitchNode(Node):
    """Holds one bool (`enabled`), set over /enable and read over /get_state."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('switch', **kwargs)
        declare(self, 'enabled', False, 'Whether the robot starts enabled')
        self.enabled = bool(self.get_parameter('enabled').value)
        self.enable_srv = self.create_service(SetBool, 'enable', self.enable_callback)
        self.state_srv = self.create_service(Trigger, 'get_state', self.state_callback)
        declare(self, 'service_configure_introspection', 'disabled',
                'Service introspection of /enable and /get_state: disabled, metadata or contents')
        self._introspect(str(self.get_parameter('service_configure_introspection').value))
        self.add_post_set_parameters_callback(self._on_parameters)
        self.get_logger().info(f'Switch node started ({self._state()})')

    def _introspect(self, state: str) -> None:
        from rclpy.qos import qos_profile_services_default
        from rclpy.service_introspection import ServiceIntrospectionState

        value = getattr(ServiceIntrospectionState, state.upper(), None)
        if value is None:
            self.get_logger().warning(f"Unknown service introspection state '{state}' "
                                      '(use disabled, metadata or contents)')
            return
        for srv in (self.enable_srv, self.state_srv):
            srv.configure_introspection(self.get_clock(), qos_profile_services_default, value)

    def _on_parameters(self, parameters: list[Any]) -> None:
        for parameter in parameters:
            if parameter.name == 'service_configure_introspection':
                self._introspect(str(parameter.value))

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
