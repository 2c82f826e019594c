"""`ros2 run tf2_ros static_transform_publisher`, with Jazzy's command line.

Jazzy's flags (`--x --y --z`, `--qx ... --qw` or `--roll --pitch --yaw`, `--frame-id`,
`--child-frame-id`) and the old positional form (x y z yaw pitch roll parent child, or
x y z qx qy qz qw parent child) with its deprecation warning; the parse errors, usage text
and the node's read-only parameters are upstream's
(tf2_ros/src/static_transform_broadcaster_program.cpp and _node.cpp).
"""

from __future__ import annotations

import random
import string
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from rclpy.impl.rcutils_logger import RcutilsLogger
from rclpy.node import Node

from robot_lab.tf2.broadcasters import StaticTransformBroadcaster
from robot_lab.tf2.linear_math import quaternion_from_euler

USAGE = (
    'usage: static_transform_publisher [--x X] [--y Y] [--z Z] [--qx QX] [--qy QY] '
    '[--qz QZ] [--qw QW] [--roll ROLL] [--pitch PITCH] [--yaw YAW] --frame-id FRAME_ID '
    '--child-frame-id CHILD_FRAME_ID\n\n'
    'A command line utility for manually sending a static transform.\n\nIf no translation or'
    ' orientation is provided, the identity transform will be published.\n\nThe translation '
    'offsets are in meters.\n\nThe rotation may be provided with roll, pitch, yaw euler '
    'angles in radians, or as a quaternion.\n\n'
    'required arguments:\n'
    '  --frame-id FRAME_ID parent frame\n'
    '  --child-frame-id CHILD_FRAME_ID child frame id\n\n'
    'optional arguments:\n'
    '  --x X                 x component of translation\n'
    '  --y Y                 y component of translation\n'
    '  --z Z                 z component of translation\n'
    '  --qx QX               x component of quaternion rotation\n'
    '  --qy QY               y component of quaternion rotation\n'
    '  --qz QZ               z component of quaternion rotation\n'
    '  --qw QW               w component of quaternion rotation\n'
    '  --roll ROLL           roll component Euler rotation\n'
    '  --pitch PITCH         pitch component Euler rotation\n'
    '  --yaw YAW             yaw component Euler rotation')

_FLOATS = {'--x': 'x', '--y': 'y', '--z': 'z', '--qx': 'qx', '--qy': 'qy', '--qz': 'qz',
           '--qw': 'qw', '--roll': 'roll', '--pitch': 'pitch', '--yaw': 'yaw'}
_LOG = RcutilsLogger('')


class ParseError(Exception):
    """One of upstream's parse messages."""


@dataclass
class StaticTransform:
    """What the command line asks for."""

    translation: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rotation: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])
    frame_id: str = ''
    child_frame_id: str = ''
    help: bool = False


def _float(name: str, text: str) -> float:
    """std::stod: a leading number is enough ('1.5m' reads 1.5), nothing numeric fails."""
    for end in range(len(text), 0, -1):
        try:
            return float(text[:end])
        except ValueError:
            continue
    raise ParseError(f'Failed to parse {name} argument as float')


def parse_args(args: Sequence[str]) -> StaticTransform:
    """parse_args of the upstream program (args[0] is the program)."""
    if len(args) < 1:
        raise ParseError('Not enough arguments to parse')
    out = StaticTransform()
    seen_frame = seen_quat = seen_rpy = seen_trans = False
    rpy = [0.0, 0.0, 0.0]
    positional: list[str] = []
    i = 1
    while i < len(args):
        name = args[i]
        if name in ('--help', '-h'):
            out.help = True
        elif name in _FLOATS or name in ('--frame-id', '--child-frame-id'):
            if i == len(args) - 1:
                raise ParseError(f'Not enough arguments for {name}')
            i += 1
            if name == '--frame-id':
                out.frame_id, seen_frame = args[i], True
            elif name == '--child-frame-id':
                out.child_frame_id, seen_frame = args[i], True
            else:
                value = _float(name, args[i])
                key = _FLOATS[name]
                if key in ('x', 'y', 'z'):
                    out.translation['xyz'.index(key)], seen_trans = value, True
                elif key in ('roll', 'pitch', 'yaw'):
                    rpy[('roll', 'pitch', 'yaw').index(key)], seen_rpy = value, True
                else:
                    out.rotation[('qx', 'qy', 'qz', 'qw').index(key)], seen_quat = value, True
        else:
            positional.append(name)
        i += 1
    if out.help:
        return out
    if seen_rpy and seen_quat:
        raise ParseError('Cannot specify both quaternion and Euler rotations')
    if seen_rpy:
        out.rotation = list(quaternion_from_euler(*rpy))
    if len(positional) in (8, 9):
        _LOG.warning('Old-style arguments are deprecated; see --help for new-style arguments')
        if seen_frame or seen_trans or seen_quat:
            raise ParseError('Cannot specify both new-style (flags) and old-style (arguments)')
        out.translation = [_float(n, v) for n, v in zip('xyz', positional, strict=False)]
        if len(positional) == 8:
            yaw, pitch, roll = (_float(n, v) for n, v in
                                zip(('yaw', 'pitch', 'roll'), positional[3:6], strict=True))
            out.rotation = list(quaternion_from_euler(roll, pitch, yaw))
            out.frame_id, out.child_frame_id = positional[6], positional[7]
        else:
            out.rotation = [_float(n, v) for n, v in
                            zip(('qx', 'qy', 'qz', 'qw'), positional[3:7], strict=True)]
            out.frame_id, out.child_frame_id = positional[7], positional[8]
    elif positional:
        raise ParseError('Extra unparsed arguments on command-line')
    if not out.frame_id:
        raise ParseError('Frame id must not be empty')
    if not out.child_frame_id:
        raise ParseError('Child frame id must not be empty')
    return out


def _node_name() -> str:
    chars = string.digits + string.ascii_letters
    return 'static_transform_publisher_' + ''.join(random.choice(chars) for _ in range(16))


class _BroadcasterNode(Node):
    """StaticTransformBroadcasterNode: a node holding its broadcaster."""

    broadcaster: StaticTransformBroadcaster


def make_node(asked: StaticTransform) -> Any:
    """The StaticTransformBroadcasterNode: read-only parameters, one latched message."""
    from geometry_msgs.msg import TransformStamped
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.parameter import Parameter

    values = {'translation.x': asked.translation[0], 'translation.y': asked.translation[1],
              'translation.z': asked.translation[2], 'rotation.x': asked.rotation[0],
              'rotation.y': asked.rotation[1], 'rotation.z': asked.rotation[2],
              'rotation.w': asked.rotation[3], 'frame_id': asked.frame_id,
              'child_frame_id': asked.child_frame_id}
    node: Any = _BroadcasterNode(_node_name(), parameter_overrides=[Parameter(k, value=v)
                                                               for k, v in values.items()])
    read_only = ParameterDescriptor(read_only=True)
    msg = TransformStamped()
    msg.header.stamp = node.get_clock().now().to_msg()
    t, r = msg.transform.translation, msg.transform.rotation
    t.x = node.declare_parameter('translation.x', 0.0, read_only).value
    t.y = node.declare_parameter('translation.y', 0.0, read_only).value
    t.z = node.declare_parameter('translation.z', 0.0, read_only).value
    r.x = node.declare_parameter('rotation.x', 0.0, read_only).value
    r.y = node.declare_parameter('rotation.y', 0.0, read_only).value
    r.z = node.declare_parameter('rotation.z', 0.0, read_only).value
    r.w = node.declare_parameter('rotation.w', 1.0, read_only).value
    msg.header.frame_id = node.declare_parameter('frame_id', '/frame', read_only).value
    msg.child_frame_id = node.declare_parameter('child_frame_id', '/child', read_only).value
    if msg.header.frame_id == msg.child_frame_id:
        node.get_logger().error(f"cannot publish static transform from '{msg.header.frame_id}' "
                                f"to '{msg.child_frame_id}', exiting")
        raise RuntimeError('child_frame_id cannot equal frame_id')
    node.broadcaster = StaticTransformBroadcaster(node)
    node.broadcaster.sendTransform(msg)
    tx, ty, tz = asked.translation
    qx, qy, qz, qw = asked.rotation
    node.get_logger().info(
        'Spinning until stopped - publishing transform\ntranslation: '
        f"('{tx:f}', '{ty:f}', '{tz:f}')\nrotation: ('{qx:f}', '{qy:f}', '{qz:f}', '{qw:f}')"
        f"\nfrom '{asked.frame_id}' to '{asked.child_frame_id}'")
    return node


def version_line(program: str) -> str:
    from robot_lab import __version__
    return (f"{program} (robot_lab {__version__}): robot_lab's tf2 (robot_lab.tf2), "
            "not geometry2's")


def main(argv: Sequence[str] | None = None) -> None:
    from rclpy.utilities import remove_ros_args

    from robot_lab.nodes.base import run_node

    full = list(sys.argv if argv is None else argv)
    args = remove_ros_args(full)
    if '--version' in args[1:]:
        print(version_line('static_transform_publisher'))
        return
    try:
        asked = parse_args(args)
    except ParseError as exc:
        _LOG.error(f'error parsing command line arguments: {exc}')
        print(USAGE, flush=True)
        sys.exit(1)
    if asked.help:
        print(USAGE, flush=True)
        return
    try:
        run_node(lambda: make_node(asked), full)
    except RuntimeError as exc:
        if 'child_frame_id cannot equal frame_id' not in str(exc):
            raise
        sys.exit(1)
