"""`ros2 run robot_state_publisher robot_state_publisher`: a URDF's links on /tf.

As Jazzy's (C++, not on PyPI): the parameter `robot_description` holds the URDF, which is
published on /robot_description at depth 1, transient-local, so a subscriber that starts
later still gets it. Fixed joints go once to /tf_static; a moving joint's transform goes
to /tf each time /joint_states names it, stamped with that message's stamp, at most every
1/`publish_frequency` s per joint unless `ignore_timestamp`. Mimic joints follow their
leader. Every frame name is prefixed with `frame_prefix`. A URDF that cannot be read is
one line naming the line of the description at fault and the fix, and the node exits 1.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from geometry_msgs.msg import TransformStamped
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from robot_lab.errors import UrdfError
from robot_lab.nodes.base import run_node
from robot_lab.urdf.kinematics import Pose, joint_pose, mimic_positions
from robot_lab.urdf.model import Joint, Robot, parse_urdf

__all__ = ['RobotStatePublisher', 'main', 'static_qos', 'tf_qos']

SOURCE = 'robot_description'  # how errors name the URDF: it came as a parameter


def tf_qos() -> QoSProfile:
    """tf2_ros.TransformBroadcaster's: depth 100, volatile."""
    return QoSProfile(depth=100)


def static_qos() -> QoSProfile:
    """StaticTransformBroadcaster's and /robot_description's: depth 1, transient-local."""
    return QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def transform_message(pose: Pose, parent: str, child: str, stamp: Any) -> TransformStamped:
    message = TransformStamped()
    message.header.stamp = stamp
    message.header.frame_id = parent
    message.child_frame_id = child
    t = message.transform.translation
    t.x, t.y, t.z = pose.translation
    q = message.transform.rotation
    q.x, q.y, q.z, q.w = pose.quaternion()
    return message


class RobotStatePublisher(Node):
    def __init__(self, description_file: str | None = None, **kwargs: Any) -> None:
        super().__init__('robot_state_publisher', **kwargs)
        text = self.declare_parameter(
            'robot_description', '',
            ParameterDescriptor(description='the URDF (XML text) to publish')).value
        if not text:
            text = self._description_from_file(description_file)
        frequency = self.declare_parameter(
            'publish_frequency', 20.0,
            ParameterDescriptor(description='most /tf messages per joint per second')).value
        if not 0.0 <= frequency <= 1000.0:
            raise UrdfError(f'publish_frequency is {frequency}; it must be between 0 and 1000',
                            fix='pass e.g. -p publish_frequency:=20.0')
        self.declare_parameter('frame_prefix', '', ParameterDescriptor(
            description='prepended to every frame name (e.g. robot1/)'))
        self.declare_parameter('ignore_timestamp', False, ParameterDescriptor(
            description='publish every /joint_states message, whatever its stamp'))
        self.robot: Robot | None = None
        self.moving: dict[str, Joint] = {}
        self.last_published: dict[str, int] = {}  # joint -> stamp (ns) last sent
        self.last_callback = 0
        self.tf = self.create_publisher(TFMessage, '/tf', tf_qos())
        self.tf_static = self.create_publisher(TFMessage, '/tf_static', static_qos())
        self.static_sent: dict[str, TransformStamped] = {}  # child frame -> transform
        self.description = self.create_publisher(String, 'robot_description', static_qos())
        self.setup(text)
        self.create_subscription(JointState, 'joint_states', self.on_joint_state,
                                 qos_profile_sensor_data)
        self.publish_fixed_transforms()
        self.add_on_set_parameters_callback(self.check_parameters)
        self.add_post_set_parameters_callback(self.parameters_set)

    def _description_from_file(self, description_file: str | None) -> str:
        """Upstream's deprecated fallback: a URDF file named as the first argument."""
        if description_file is None:
            raise UrdfError('robot_description parameter must not be empty',
                            fix='pass the URDF: --ros-args -p robot_description:="$(xacro '
                                'model.urdf)" (a launch file: Command([\'xacro \', path]))')
        self.get_logger().warn(
            'No robot_description parameter, but command-line argument available.  Assuming '
            'argument is name of URDF file.  This backwards compatibility fallback will be '
            'removed in the future.')
        try:
            text = Path(description_file).read_text()
        except OSError as exc:
            raise UrdfError(f'Failed to open URDF file: {description_file} ({exc.strerror})',
                            fix='check the path') from None
        self.set_parameters([Parameter('robot_description', value=text)])
        return text

    def setup(self, text: str) -> None:
        """Read the URDF, sort its joints into moving and fixed, publish the description."""
        robot = parse_urdf(text, SOURCE)
        self.robot = robot
        self.moving = {j.name: j for j in robot.joints.values() if j.moves}
        self.description.publish(String(data=text))
        self.get_logger().info('Robot initialized')

    def _frame(self, name: str) -> str:
        return str(self.get_parameter('frame_prefix').value) + name

    def publish_fixed_transforms(self) -> None:
        """Fixed (and planar) joints on /tf_static; floating joints are skipped, as KDL's."""
        assert self.robot is not None
        stamp = self.get_clock().now().to_msg()
        for joint in self.robot.joints.values():
            if joint.moves or joint.type == 'floating':
                continue
            message = transform_message(joint_pose(joint), self._frame(joint.parent),
                                        self._frame(joint.child), stamp)
            self.static_sent[message.child_frame_id] = message
        # As tf2_ros's StaticTransformBroadcaster: one latched message holding them all.
        self.tf_static.publish(TFMessage(transforms=list(self.static_sent.values())))

    def on_joint_state(self, state: JointState) -> None:
        if len(state.name) != len(state.position):
            if not state.position:
                self.get_logger().warn(
                    'Robot state publisher ignored a JointState message about joint(s) '
                    f'"{state.name[0] if state.name else ""}"(,...) whose position member '
                    'was empty.')
            else:
                self.get_logger().error(
                    'Robot state publisher ignored an invalid JointState message')
            return
        now = self.get_clock().now().nanoseconds
        if self.last_callback > now:  # a bag played again: time went backwards
            self.get_logger().warn('Moved backwards in time, re-publishing joint transforms!')
            self.last_published.clear()
        self.last_callback = now
        least_recent = min((self.last_published.get(n, 0) for n in state.name), default=now)
        least_recent = min(least_recent, now)
        stamp_ns = state.header.stamp.sec * 1_000_000_000 + state.header.stamp.nanosec
        frequency = float(self.get_parameter('publish_frequency').value)
        interval = int(1000.0 / frequency) * 1_000_000 if frequency > 0 else 2**62
        if not (self.get_parameter('ignore_timestamp').value
                or stamp_ns >= least_recent + interval):
            return
        self.publish_transforms(dict(zip(state.name, state.position, strict=True)),
                                state.header.stamp)
        for name in state.name:
            self.last_published[name] = stamp_ns

    def publish_transforms(self, positions: dict[str, float], stamp: Any) -> None:
        """One /tf message: each moving joint named in `positions` (or mimicking one)."""
        assert self.robot is not None
        full = mimic_positions(self.robot, {n: float(p) for n, p in positions.items()})
        transforms = [
            transform_message(joint_pose(joint, full[name]), self._frame(joint.parent),
                              self._frame(joint.child), stamp)
            for name, joint in sorted(self.moving.items()) if name in full
        ]
        self.tf.publish(TFMessage(transforms=transforms))

    def check_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        """Refuse an empty or unreadable URDF and a frequency out of range, as upstream."""
        for parameter in parameters:
            if parameter.name == 'robot_description':
                if not parameter.value:
                    return SetParametersResult(successful=False,
                                               reason='Empty URDF is not allowed')
                try:
                    parse_urdf(str(parameter.value), SOURCE)
                except UrdfError as err:
                    self.get_logger().warn(str(err))
                    return SetParametersResult(successful=False, reason=str(err))
            elif parameter.name == 'publish_frequency':
                value = parameter.value
                if not isinstance(value, float) or not 0.0 <= value <= 1000.0:
                    return SetParametersResult(
                        successful=False,
                        reason='publish_frequency must be between 0.0 and 1000.0')
        return SetParametersResult(successful=True)

    def parameters_set(self, parameters: list[Parameter]) -> None:
        """A new robot_description: read it again and send its fixed joints."""
        for parameter in parameters:
            if parameter.name == 'robot_description' and self.robot is not None:
                self.setup(str(parameter.value))
                self.publish_fixed_transforms()


def main(args: Sequence[str] | None = None) -> None:
    """The `robot_state_publisher` executable: a URDF error is one line and exit code 1."""
    import rclpy.utilities

    argv = list(sys.argv if args is None else args)
    plain = rclpy.utilities.remove_ros_args(args=argv)[1:]
    description_file = plain[0] if plain else None
    try:
        run_node(lambda: RobotStatePublisher(description_file), argv)
    except UrdfError as err:
        print(f'[FATAL] [robot_state_publisher]: {err}', file=sys.stderr, flush=True)
        sys.exit(1)


if __name__ == '__main__':
    main()
