"""`ros2 run ros_gz_sim create`: put a robot into the running simulation, as Jazzy's does.

Its arguments are upstream's gflags-style ones: `-world`, `-file F`, `-string XML`, `-topic
T` (a std_msgs/String, transient-local, as robot_state_publisher latches
/robot_description), `-param P` (the XML in the create node's ROS parameter P), `-name N`,
`-allow_renaming`, `-x -y -z -R -P -Y`; and upstream's ROS parameters of the same names
(`--ros-args -p file:=F -p name:=N`, or a launch file's `parameters=[...]`), which win over
the flags as upstream's do. The XML is a URDF `<robot>` (its `<gazebo>` systems run) or an
SDF `<model>`. The robot goes to the simulation of this partition (`transport`); the answer
is upstream's log line, `Entity creation successful.`, or the simulator's refusal.
"""

from __future__ import annotations

import itertools
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from robot_lab.sim.about import identity
from robot_lab.sim.transport import Connection, connect, socket_path

__all__ = ['main', 'parse_create_args']

_NUMBERS = ('x', 'y', 'z', 'R', 'P', 'Y')
_TEXTS = ('world', 'file', 'string', 'topic', 'name', 'param')
WAIT_FOR_SIMULATION = 30.0  # seconds: the simulation may still be starting (a launch file)


def parse_create_args(argv: Sequence[str]) -> tuple[dict[str, Any], list[str]]:
    """Upstream's flags (`-x 1`, `-x=1`, `--x 1`) and the `--ros-args` that follow."""
    options: dict[str, Any] = {k: 0.0 for k in _NUMBERS}
    options['allow_renaming'] = False
    rest = list(argv)
    ros_args: list[str] = []
    if '--ros-args' in rest:
        ros_args = rest[rest.index('--ros-args'):]
        rest = rest[:rest.index('--ros-args')]
    items = iter(rest)
    for item in items:
        flag, _, value = item.lstrip('-').partition('=')
        if flag == 'allow_renaming':
            options['allow_renaming'] = value.lower() not in ('false', '0')
            continue
        if flag not in _NUMBERS and flag not in _TEXTS:
            raise SystemExit(f'create: unknown flag {item!r}; flags: -world -file -string -topic '
                             f'-param -name -allow_renaming -x -y -z -R -P -Y')
        if not value:
            value = next(items, '')
        options[flag] = float(value) if flag in _NUMBERS else value
    return options, ros_args


def _ros_node(ros_args: list[str]) -> Any:
    """The create node (`ros_gz_sim`, as upstream names it), with every parameter it was
    given declared, so -param and the ROS-parameter form can read them."""
    import rclpy

    rclpy.init(args=['create', *ros_args])
    return rclpy.create_node('ros_gz_sim',
                             automatically_declare_parameters_from_overrides=True)


def _from_topic(topic: str, node: Any) -> str:
    import rclpy
    from std_msgs.msg import String

    from robot_lab.urdf.state_publisher import description_qos

    received: list[str] = []

    def take(msg: Any) -> None:
        received.append(str(msg.data))

    node.create_subscription(String, topic, take, description_qos())
    node.get_logger().info(f'Waiting messages on topic [{topic}].')
    while not received:
        rclpy.spin_once(node, timeout_sec=0.5)
    return received[0]  # the loop above ends only once one arrived


def _with_ros_parameters(options: dict[str, Any], node: Any) -> None:
    """Upstream's ROS parameters (world, file, string, topic, name, allow_renaming, x ...
    Y): a file, string or topic given so replaces the flags' source; a pose value or name
    given non-zero replaces the flag's."""
    values = {name: p.value for name, p in node.get_parameters_by_prefix('').items()}
    sources = [k for k in ('file', 'string', 'topic') if values.get(k)]
    if sources:
        for key in ('file', 'string', 'topic', 'param'):
            options[key] = values[sources[0]] if key == sources[0] else ''
    for key in ('world', 'name'):
        if values.get(key):
            options[key] = str(values[key])
    for key in _NUMBERS:
        options[key] = float(values.get(key) or 0.0) or options[key]
    options['allow_renaming'] = bool(values.get('allow_renaming')) or options['allow_renaming']


def _description(options: dict[str, Any], ros_args: list[str]) -> tuple[str, str] | None:
    """(the XML, where it came from), or None after upstream's error line."""
    needs_ros = options.get('topic') or options.get('param') or any(
        a in ('-p', '--param', '--params-file') for a in ros_args)
    node = _ros_node(ros_args) if needs_ros else None
    try:
        if node is not None:
            _with_ros_parameters(options, node)
        if options.get('file'):
            return Path(options['file']).expanduser().read_text(), str(options['file'])
        if options.get('param'):
            value = node.get_parameter_or(options['param']).value if node else None
            if not isinstance(value, str) or not value:
                print(f'[ERROR] [ros_gz_sim]: Failed to get XML from param '
                      f'[{options["param"]}].', flush=True)
                return None
            return value, f'parameter {options["param"]}'
        if options.get('string'):
            return str(options['string']), 'robot_description'
        if options.get('topic') and node is not None:
            return _from_topic(options['topic'], node), str(options['topic'])
        print('[ERROR] [ros_gz_sim]: Must specify either -file, -param, -string or -topic',
              flush=True)
        return None
    finally:
        if node is not None:
            import rclpy.utilities

            node.destroy_node()
            rclpy.utilities.try_shutdown()


def _wait_for_simulation() -> Connection | None:
    deadline = time.monotonic() + WAIT_FOR_SIMULATION
    while time.monotonic() < deadline:
        connection = connect()
        if connection is not None:
            return connection
        time.sleep(0.1)  # polling the socket: the simulator announces nothing before it binds
    return None


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if '--version' in args:
        print(identity())
        return 0
    options, ros_args = parse_create_args(args)
    print(f'[INFO] [ros_gz_sim]: {identity()}', flush=True)
    found = _description(options, ros_args)
    if found is None:
        return 1
    text, source = found
    connection = _wait_for_simulation()
    if connection is None:
        print(f'[ERROR] [ros_gz_sim]: no simulation answers on {socket_path()} after '
              f'{WAIT_FOR_SIMULATION:g} s: start one with `ros2 launch ros_gz_sim '
              f'gz_sim.launch.py gz_args:="-r empty.sdf"` (same ROS_DOMAIN_ID / GZ_PARTITION)',
              flush=True)
        return 1
    name = options.get('name') or ''  # '' : the URDF's robot name, the SDF model's name
    ids = itertools.count(1)
    for attempt in range(100 if options['allow_renaming'] and name else 1):
        request = name if attempt == 0 else f'{name}_{attempt}'
        connection.send({'op': 'create', 'id': next(ids), 'urdf': text, 'name': request,
                         'source': source, 'world': options.get('world') or '',
                         'xyz': [options['x'], options['y'], options['z']],
                         'rpy': [options['R'], options['P'], options['Y']]})
        reply = connection.receive()
        if reply is not None and reply.get('ok'):
            print('[INFO] [ros_gz_sim]: Entity creation successful.', flush=True)
            connection.close()
            return 0
        error = reply.get('error', '') if reply else 'the simulation closed the connection'
        if 'already exists' not in str(error):
            break
    print(f'[ERROR] [ros_gz_sim]: Entity creation failed: {error}', flush=True)
    connection.close()
    return 1


if __name__ == '__main__':
    sys.exit(main())
