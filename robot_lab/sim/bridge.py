"""`ros2 run ros_gz_bridge parameter_bridge`: where the simulator's topics become ROS topics.

Upstream's syntax, on the command line (`TOPIC@ROS_TYPE]GZ_TYPE` ROS -> gz,
`TOPIC@ROS_TYPE[GZ_TYPE` gz -> ROS, `TOPIC@ROS_TYPE@GZ_TYPE` both) or in a YAML file
(`--ros-args -p config_file:=bridge.yaml`: a list of entries with `ros_topic_name`,
`gz_topic_name` or `topic_name`, `ros_type_name`, `gz_type_name`, `direction`
BIDIRECTIONAL | GZ_TO_ROS | ROS_TO_GZ), as a node named `ros_gz_bridge` (so a launch file's
`Node(package='ros_gz_bridge', executable='parameter_bridge', ...)` runs unchanged). A
service, as upstream's jazzy bridges one (`/world/<name>/control@ros_gz_interfaces/srv/
ControlWorld[@gz.msgs.WorldControl@gz.msgs.Boolean]`), becomes a ROS service that asks
the simulation's world control and answers `success`. The
simulation may start before or after the bridge; the bridge waits for it and reconnects if
it restarts, as gz-transport's discovery would.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
import sys
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from robot_lab.sim.about import identity
from robot_lab.sim.conversions import PAIRS, SERVICES, from_gz, to_gz, world_control_request
from robot_lab.sim.transport import Connection, connect, topic_name

__all__ = ['BridgeSpec', 'ServiceSpec', 'main', 'parse_bridge_arg', 'parse_bridge_config',
           'parse_service_arg']

_ARG = re.compile(r'^(?P<topic>[^@\[\]]+)@(?P<ros>[^@\[\]]+)(?P<dir>[@\[\]])(?P<gz>[^@\[\]]+)$')
_SERVICE = re.compile(r'^(?P<name>[^@\[\]]+)@(?P<ros>[^@\[\]]+/srv/[^@\[\]]+)'
                      r'(?:@(?P<req>[^@\[\]]+)@(?P<rep>[^@\[\]]+))?$')
_DIRECTIONS = {'@': 'BIDIRECTIONAL', '[': 'GZ_TO_ROS', ']': 'ROS_TO_GZ'}
USAGE = ('Usage: parameter_bridge [<topic@ROS2_type@Gz_type> ..]  [<topic@ROS2_type[Gz_type> ..]'
         '  [<topic@ROS2_type]Gz_type> ..] [<service@ROS2_srv_type[@Gz_req_type@Gz_rep_type]> ..]'
         ' [--ros-args -p config_file:=<path_to_config_file>]')


@dataclass(frozen=True)
class BridgeSpec:
    """One bridged topic: its ROS and gz names and types, and which way it goes."""

    ros_topic: str
    gz_topic: str
    ros_type: str
    gz_type: str
    direction: str  # BIDIRECTIONAL | GZ_TO_ROS | ROS_TO_GZ
    publisher_queue: int = 10  # upstream's defaults
    subscriber_queue: int = 10
    lazy: bool = False  # no effect on what arrives; said in the log line, as upstream

    def check(self, where: str) -> None:
        """Refuse a pair or direction the kit does not convert, naming what it does."""
        directions = PAIRS.get((self.ros_type, self.gz_type))
        wanted = {'GZ_TO_ROS': {'gz_to_ros'}, 'ROS_TO_GZ': {'ros_to_gz'},
                  'BIDIRECTIONAL': {'gz_to_ros', 'ros_to_gz'}}[self.direction]
        if directions is None or not wanted <= directions:
            known = ', '.join(f'{r} {"<->" if len(d) == 2 else "<-"} {g}'
                              for (r, g), d in PAIRS.items())
            raise SystemExit(f"{where}: robot_lab's bridge does not convert {self.ros_type} "
                             f'{self.direction} {self.gz_type}; it converts: {known}')


def parse_bridge_arg(arg: str) -> BridgeSpec:
    """`/cmd_vel@geometry_msgs/msg/Twist]gz.msgs.Twist` -> a BridgeSpec."""
    match = _ARG.match(arg)
    if match is None:
        raise SystemExit(f'parameter_bridge: {arg!r} is not TOPIC@ROS_TYPE(@|[|])GZ_TYPE\n{USAGE}')
    topic = match['topic']
    return BridgeSpec(topic, topic, match['ros'], match['gz'], _DIRECTIONS[match['dir']])


@dataclass(frozen=True)
class ServiceSpec:
    """One bridged service: a ROS service that forwards to the simulation's gz service."""

    name: str
    ros_type: str
    gz_request: str
    gz_reply: str


def parse_service_arg(arg: str) -> ServiceSpec | None:
    """`/world/room/control@ros_gz_interfaces/srv/ControlWorld` -> a ServiceSpec (None if
    `arg` names no service); a service the kit does not bridge: one line naming it."""
    match = _SERVICE.match(arg)
    if match is None:
        return None
    types = SERVICES.get(match['ros'])
    if types is None or (match['req'] and (match['req'], match['rep']) != types):
        known = ', '.join(f'{ros}@{req}@{rep}' for ros, (req, rep) in SERVICES.items())
        raise SystemExit(f"parameter_bridge: {arg!r}: robot_lab's bridge does not bridge this "
                         f'service; it bridges: {known}')
    if not re.fullmatch(r'/world/[^/]+/control', match['name']):
        raise SystemExit(f"parameter_bridge: {arg!r}: robot_lab's simulator serves "
                         f'/world/<name>/control only; write /world/<world name>/control')
    return ServiceSpec(match['name'], match['ros'], *types)


def serve_world_control(node: Any, spec: ServiceSpec) -> Any:
    """The ROS service: each request goes to the simulation of this partition as a
    WorldControl; `success` is false when none answers (as upstream's on a timeout)."""
    from robot_lab.messages import message_class
    from robot_lab.sim.control import world_control
    from robot_lab.sim.xml_tree import SimulationError

    def call(request: Any, response: Any) -> Any:
        frame, unsupported = world_control_request(request.world_control)
        if unsupported:
            node.get_logger().warning(
                f'{spec.name}: {", ".join(unsupported)} not supported (by Gazebo either): '
                f'ignored')
        try:
            world_control(pause=frame['pause'], step=frame['multi_step'], reset=frame['reset'],
                          world=spec.name.split('/')[2],
                          run_to=frame.get('run_to_sim_time', 0) / 1e9)
            response.success = True
        except SimulationError as error:
            node.get_logger().error(f'{spec.name}: {error}')
            response.success = False
        return response

    node.get_logger().info(f'Creating ROS service bridge: [{spec.name} ({spec.ros_type}) -> '
                           f'{spec.gz_request}/{spec.gz_reply}]')
    return node.create_service(message_class(spec.ros_type), spec.name, call)


_ENTRY_KEYS = {'topic_name', 'ros_topic_name', 'gz_topic_name', 'ros_type_name',
               'gz_type_name', 'direction', 'publisher_queue', 'subscriber_queue', 'lazy'}


def parse_bridge_config(path: str, warn: Any = print) -> list[BridgeSpec]:
    """A ros_gz_bridge YAML config file's entries, read as upstream's bridge_config.cpp
    reads them: topic_name, or ros_topic_name and/or gz_topic_name (one given names both);
    both types; direction; publisher_queue, subscriber_queue, lazy. A mistake stops it
    with `file:line`; a key upstream does not read is one `warn` line."""
    text = Path(path).read_text()
    entries = yaml.safe_load(text) or []
    root = yaml.compose(text)
    lines = [n.start_mark.line + 1 for n in root.value] if isinstance(
        root, yaml.SequenceNode) else []
    if not isinstance(entries, list):
        raise SystemExit(f'{path}:1: Could not parse config: top level must be a YAML '
                         f'sequence (a list of entries, each "- topic_name: ...")')
    specs = []
    for index, entry in enumerate(entries):
        where = f'{path}:{lines[index] if index < len(lines) else 1}'
        if not isinstance(entry, dict):
            raise SystemExit(f'{where}: an entry is a mapping (topic_name: ..., '
                             f'ros_type_name: ..., gz_type_name: ...)')
        for other in ('ros_topic_name', 'gz_topic_name'):
            if entry.get('topic_name') and entry.get(other):
                raise SystemExit(f'{where}: topic_name and {other} are mutually exclusive')
        ros_topic = entry.get('topic_name') or entry.get('ros_topic_name') or \
            entry.get('gz_topic_name')
        gz_topic = entry.get('topic_name') or entry.get('gz_topic_name') or \
            entry.get('ros_topic_name')
        if not ros_topic or not entry.get('ros_type_name') or not entry.get('gz_type_name'):
            raise SystemExit(f'{where}: needs topic_name (or ros_topic_name and/or '
                             f'gz_topic_name), ros_type_name and gz_type_name')
        direction = str(entry.get('direction', 'BIDIRECTIONAL')).upper()
        if direction not in _DIRECTIONS.values():
            raise SystemExit(f'{where}: direction {direction!r}: BIDIRECTIONAL, GZ_TO_ROS or '
                             f'ROS_TO_GZ')
        for key in sorted(set(entry) - _ENTRY_KEYS):
            warn(f'{where}: {key!r} is not a ros_gz_bridge entry key '
                 f'({", ".join(sorted(_ENTRY_KEYS))}); ignored')
        specs.append(BridgeSpec(str(ros_topic), str(gz_topic), str(entry['ros_type_name']),
                                str(entry['gz_type_name']), direction,
                                int(entry.get('publisher_queue', 10)),
                                int(entry.get('subscriber_queue', 10)),
                                bool(entry.get('lazy', False))))
    return specs


class Bridge:
    """The node's publishers and subscriptions, and the connection to the simulation."""

    def __init__(self, node: Any, specs: list[BridgeSpec]) -> None:
        from robot_lab.messages import message_class

        self.node = node
        self.connection: Connection | None = None
        self.to_ros: dict[str, list[tuple[BridgeSpec, Any, Any]]] = {}
        self.last_sent: dict[str, Any] = {}
        for spec in specs:
            cls = message_class(spec.ros_type)
            arrow = {'GZ_TO_ROS': 'GZ->ROS', 'ROS_TO_GZ': 'ROS->GZ'}.get(spec.direction, 'GZ<->ROS')
            ends = [f'{spec.gz_topic} ({spec.gz_type})', f'{spec.ros_topic} ({spec.ros_type})']
            if spec.direction == 'ROS_TO_GZ':
                ends.reverse()
            node.get_logger().info(f'Creating {arrow} Bridge: [{ends[0]} -> {ends[1]}] '
                                   f'(Lazy {int(spec.lazy)})')
            if spec.direction in ('GZ_TO_ROS', 'BIDIRECTIONAL'):
                qos = self._qos(spec.ros_topic, spec.publisher_queue)
                publisher = node.create_publisher(cls, spec.ros_topic, qos)
                self.to_ros.setdefault(topic_name(spec.gz_topic), []).append((spec, cls, publisher))
            if spec.direction in ('ROS_TO_GZ', 'BIDIRECTIONAL'):
                node.create_subscription(cls, spec.ros_topic,
                                         lambda msg, s=spec: self._to_gz(s, msg),
                                         spec.subscriber_queue)
        self.stopping = threading.Event()
        self.link = threading.Thread(target=self._link, daemon=True)
        self.link.start()

    def stop(self) -> None:
        """End the relay before rclpy's node goes: a publish racing the node's destruction
        at interpreter exit can deadlock in the middleware (seen once on SIGTERM)."""
        self.stopping.set()
        connection = self.connection
        if connection is not None:
            connection.close()  # its receive() returns None at once
        self.link.join(timeout=2.0)

    @staticmethod
    def _qos(topic: str, depth: int) -> Any:
        from rclpy.qos import DurabilityPolicy, QoSProfile

        if topic.endswith('tf_static'):  # as upstream: latched for late listeners
            return QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        return QoSProfile(depth=depth)

    def _to_gz(self, spec: BridgeSpec, msg: Any) -> None:
        if self.last_sent.get(spec.ros_topic) is msg:
            return
        connection = self.connection
        if connection is not None:
            connection.send({'op': 'pub', 'topic': topic_name(spec.gz_topic), 'type': spec.gz_type,
                             'msg': to_gz(spec.gz_type, msg)})

    def _link(self) -> None:
        """Connect to the simulation (waiting for it), subscribe, relay; again if it ends."""
        while not self.stopping.is_set():
            connection = connect()
            if connection is None:
                self.stopping.wait(0.1)  # polling the socket: no simulation announces its start
                continue
            for topic in self.to_ros:
                connection.send({'op': 'sub', 'topic': topic})
            self.connection = connection
            while (frame := connection.receive()) is not None and not self.stopping.is_set():
                for spec, cls, publisher in self.to_ros.get(str(frame.get('topic')), []):
                    msg = from_gz(spec.gz_type, cls, frame['msg'])
                    if spec.direction == 'BIDIRECTIONAL':
                        self.last_sent[spec.ros_topic] = msg
                    publisher.publish(msg)
            self.connection = None


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if '--version' in args:
        print(identity())
        return 0
    cut = args.index('--ros-args') if '--ros-args' in args else len(args)
    services = [s for s in map(parse_service_arg, args[:cut]) if s is not None]
    specs = [parse_bridge_arg(a) for a in args[:cut] if parse_service_arg(a) is None]
    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init(args=['parameter_bridge', *args[cut:]])
    node = rclpy.create_node('ros_gz_bridge')
    node.get_logger().info(identity())
    config = node.declare_parameter('config_file', '').value
    if node.declare_parameter('lazy', False).value:  # upstream's: for the command line's
        specs = [dataclasses.replace(spec, lazy=True) for spec in specs]
    from_arguments = len(specs)
    if config:
        specs += parse_bridge_config(str(config), node.get_logger().warning)
    if not specs and not services:
        print(USAGE, file=sys.stderr)
        return 1
    for index, spec in enumerate(specs):
        spec.check(str(config) if index >= from_arguments else 'parameter_bridge')
    for service in services:
        serve_world_control(node, service)
    bridge = Bridge(node, specs)
    try:
        with contextlib.suppress(KeyboardInterrupt, ExternalShutdownException):  # Ctrl-C, SIGINT
            rclpy.spin(node)
    finally:
        bridge.stop()
    return 0


if __name__ == '__main__':
    sys.exit(main())
