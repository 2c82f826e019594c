"""`ros2 run joint_state_publisher joint_state_publisher`: /joint_states for a URDF.

As upstream's (pure rclpy, BSD; written here again): the URDF comes from a file named on
the command line or from /robot_description (transient-local, so it arrives even when
robot_state_publisher started first, and again when it changes). Every `rate` Hz (10) it
publishes each movable joint's position: `zeros.<joint>` or its default, what the topics
of `source_list` last said, mimic joints from their leader; `delta` sweeps the joints.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, ParameterType
from rclpy.exceptions import ParameterAlreadyDeclaredException
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from robot_lab.errors import UrdfError
from robot_lab.nodes.base import run_node
from robot_lab.urdf.joints import Dependent, JointTable, joint_table
from robot_lab.urdf.model import parse_urdf
from robot_lab.urdf.state_publisher import description_qos

__all__ = ['JointStatePublisher', 'main']

_PARAMETERS: tuple[tuple[str, Any, int], ...] = (
    ('publish_default_efforts', False, ParameterType.PARAMETER_BOOL),
    ('publish_default_positions', True, ParameterType.PARAMETER_BOOL),
    ('publish_default_velocities', False, ParameterType.PARAMETER_BOOL),
    ('rate', 10, ParameterType.PARAMETER_INTEGER),
    ('source_list', [], ParameterType.PARAMETER_STRING_ARRAY),
    ('use_mimic_tags', True, ParameterType.PARAMETER_BOOL),
    ('use_smallest_joint_limits', True, ParameterType.PARAMETER_BOOL),
    ('delta', 0.0, ParameterType.PARAMETER_DOUBLE),
)


class JointStatePublisher(Node):
    def __init__(self, description_file: str | None = None, **kwargs: Any) -> None:
        # zeros.<joint> and dependent_joints.<joint>.<key> are maps rclpy cannot declare:
        # whatever the command line gives is declared, as upstream does.
        super().__init__('joint_state_publisher',
                         automatically_declare_parameters_from_overrides=True, **kwargs)
        for name, default, kind in _PARAMETERS:
            with contextlib.suppress(ParameterAlreadyDeclaredException):  # given: declared
                self.declare_parameter(name, default, ParameterDescriptor(type=kind))
        zeros: dict[str, Any] = self.get_parameters_by_prefix('zeros')  # name -> Parameter
        self.zeros = {k: float(v.value) for k, v in zeros.items()}
        self.dependent = self._dependent_joints()
        self.table = JointTable([], {}, dict(self.dependent))
        if description_file is not None:
            self.configure(Path(description_file).read_text(), description_file)
        else:
            self.get_logger().info('Waiting for robot_description to be published on the '
                                   'robot_description topic...')
        self.create_subscription(String, 'robot_description', self.on_description,
                                 description_qos())
        self.delta = float(self.get_parameter('delta').value)
        for topic in self.get_parameter('source_list').value or []:
            self.create_subscription(JointState, topic, self.on_source, 10)
        self.publisher = self.create_publisher(JointState, 'joint_states', 10)
        self.create_timer(1.0 / int(self.get_parameter('rate').value), self.publish)

    def _dependent_joints(self) -> dict[str, Dependent]:
        fields: dict[str, dict[str, Any]] = {}
        given: dict[str, Any] = self.get_parameters_by_prefix('dependent_joints')
        for key, parameter in given.items():
            joint, _, field = key.partition('.')
            if field not in ('parent', 'factor', 'offset') or '.' in field:
                raise UrdfError(f"Invalid dependent_joint name '{key}' (allowed values are "
                                "'parent', 'factor', 'offset')",
                                fix='write dependent_joints.<joint>.parent:=<leader>')
            fields.setdefault(joint, {})[field] = parameter.value
        if any('parent' not in entry for entry in fields.values()):
            raise UrdfError('All dependent_joints must at least have a parent',
                            fix='add dependent_joints.<joint>.parent:=<leader>')
        return {name: Dependent(str(e['parent']), float(e.get('factor', 1.0)),
                                float(e.get('offset', 0.0))) for name, e in fields.items()}

    def configure(self, text: str, source: str = 'robot_description') -> None:
        robot = parse_urdf(text, source)
        self.table = joint_table(
            robot, self.zeros,
            use_mimic_tags=bool(self.get_parameter('use_mimic_tags').value),
            use_smallest_joint_limits=bool(
                self.get_parameter('use_smallest_joint_limits').value),
            dependent=self.dependent)

    def on_description(self, message: String) -> None:
        try:
            self.configure(message.data)
        except UrdfError as err:  # upstream warns and keeps the joints it had
            self.get_logger().warn(str(err))

    def on_source(self, message: JointState) -> None:
        for i, name in enumerate(message.name):
            joint = self.table.free.get(name)
            if joint is not None and i < len(message.position):
                joint.position = float(message.position[i])

    def _sweep(self) -> None:
        """`delta`: each free joint moves by delta per tick, back and forth (continuous:
        round and round), as upstream's."""
        for joint in self.table.free.values():
            joint.position += self.delta if joint.forward else -self.delta
            if joint.position > joint.upper:
                joint.position = joint.lower if joint.continuous else joint.upper
                joint.forward = joint.continuous
            elif joint.position < joint.lower:
                joint.position = joint.lower
                joint.forward = True

    def publish(self) -> None:
        if self.delta > 0:
            self._sweep()
        message = JointState()
        message.header.stamp = self.get_clock().now().to_msg()
        message.name = list(self.table.order)
        if self.get_parameter('publish_default_positions').value or self.table.dependent:
            try:
                message.position = self.table.positions()
            except ValueError as err:
                self.get_logger().error(str(err))
                raise SystemExit(1) from None
        count = len(message.name)
        if self.get_parameter('publish_default_velocities').value:
            message.velocity = [0.0] * count
        if self.get_parameter('publish_default_efforts').value:
            message.effort = [0.0] * count
        if message.name:  # upstream publishes only a non-empty message
            self.publisher.publish(message)


def main(args: Sequence[str] | None = None) -> None:
    """The `joint_state_publisher` executable (an optional URDF file argument)."""
    import rclpy.utilities

    argv = list(sys.argv if args is None else args)
    plain = rclpy.utilities.remove_ros_args(args=argv)[1:]
    try:
        run_node(lambda: JointStatePublisher(plain[0] if plain else None), argv)
    except UrdfError as err:
        print(f'[FATAL] [joint_state_publisher]: {err}', file=sys.stderr, flush=True)
        sys.exit(1)


if __name__ == '__main__':
    main()
