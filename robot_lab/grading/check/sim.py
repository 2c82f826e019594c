"""Checks of lesson 13 (a robot in the simulator): the `<gazebo>` tags, the bridge, a
controller that stops before the obstacle ahead.

Each names the mistake students make there: DiffDrive given the wheels' link names instead
of their joints, a lidar on a topic nobody bridges, a topic left out of the bridge (the
simulator publishes it, so the fix is the bridge line), a scan read in the wrong frame
(`ranges[0]` taken as straight ahead, when it is the beam at `angle_min` = −π, behind), a
controller that does not run on the simulation's clock.
"""

from __future__ import annotations

import functools
import math
import threading
import time
from pathlib import Path
from typing import Any

from robot_lab.grading.check.base import CheckError, callback_failed, judged, passed, wait_until
from robot_lab.grading.check.description import _expand, _robot

__all__ = ['bridged', 'gazebo_tags', 'reacts_to_scan', 'stops_before_obstacle']


def _same(a: float, b: float, tolerance: float = 0.005) -> bool:
    return abs(a - b) <= tolerance


def _wheel(robot: Any, root: Any, joint_name: str) -> tuple[float, float | None]:
    """A wheel joint's y in base_link and its link's cylinder radius (None: no cylinder)."""
    joint = robot.joints[joint_name]
    for link in root.findall('link'):
        if link.attrib.get('name') != joint.child:
            continue
        for part in (*link.findall('collision'), *link.findall('visual')):
            geometry = part.find('geometry')
            cylinder = geometry.find('cylinder') if geometry is not None else None
            if cylinder is not None:
                return float(joint.xyz[1]), float(cylinder.attrib.get('radius', '0'))
    return float(joint.xyz[1]), None


def _diff_drive_errors(robot: Any, root: Any, drive: Any) -> tuple[str, str] | None:
    joints = ', '.join(n for n, j in robot.joints.items() if j.type == 'continuous')
    for side, names in (('left', drive.left_joints), ('right', drive.right_joints)):
        if not names:
            return (f'DiffDrive has no <{side}_joint>',
                    f"name the {side} wheel's joint: <{side}_joint>{side}_wheel_joint"
                    f'</{side}_joint>')
        for name in names:
            if name not in robot.joints:
                kind = 'a link, not a joint' if name in robot.links else 'not in the robot'
                return (f"DiffDrive's {side}_joint is {name!r}, {kind} (the wheel joints: "
                        f'{joints or "none"})',
                        f"DiffDrive turns joints: <{side}_joint> takes the joint's name, "
                        f'e.g. {side}_wheel_joint')
            if robot.joints[name].type != 'continuous':
                return (f"DiffDrive's {side}_joint {name!r} is a {robot.joints[name].type} "
                        'joint', f"give it the {side} wheel's continuous joint")
    left_y, radius = _wheel(robot, root, drive.left_joints[0])
    right_y, _ = _wheel(robot, root, drive.right_joints[0])
    if left_y < right_y:
        return (f'<left_joint> {drive.left_joints[0]} is at y = {left_y:g}, right of the '
                'robot (the robot turns the wrong way)', 'swap <left_joint> and <right_joint>: '
                'the left wheel is at +y')
    separation = abs(left_y - right_y)
    if not _same(drive.wheel_separation, separation):
        return (f'<wheel_separation> {drive.wheel_separation:g} m (the wheel joints are '
                f'{separation:g} m apart)',
                f'write <wheel_separation>{separation:g}</wheel_separation>: the distance '
                "between the wheels' centres, in metres")
    if radius is not None and not _same(drive.wheel_radius, radius, 0.002):
        return (f'<wheel_radius> {drive.wheel_radius:g} m (the wheel cylinders have radius '
                f'{radius:g})', f'write <wheel_radius>{radius:g}</wheel_radius>: DiffDrive '
                'turns a wheel v / r rad/s, so a wrong radius drives too far or too short')
    for tag, value, wanted in (('topic', drive.topic, 'cmd_vel'),
                               ('odom_topic', drive.odom_topic, 'odom')):
        if value.strip('/') != wanted:
            return (f'DiffDrive\'s <{tag}> is {value or "not set (/model/<name>/…)"!s}',
                    f'write <{tag}>{wanted}</{tag}>: the gz topic the bridge connects to /{wanted}')
    return None


@judged
def gazebo_tags(model: str | Path, lidar_topic: str = 'scan') -> None:
    """The model (xacro or URDF) has a DiffDrive on its two wheel joints, with their
    separation and radius, on cmd_vel/odom, and a lidar on one of its links publishing
    gz topic `lidar_topic`."""
    from robot_lab.sim.gazebo_tags import read_gazebo_tags
    from robot_lab.sim.xml_tree import SimulationError, parse

    file = Path(model)
    what = f'{file.name} to tell the simulator how the robot drives and senses'
    if not file.is_file():
        raise CheckError(what, f'there is no {file.name} yet',
                         'run the cells above: they write the model')
    text = _expand(file, what) if file.name.endswith('.xacro') else file.read_text()
    robot = _robot(text, f'{file.name} (expanded)', what)
    warnings: list[str] = []
    try:
        root = parse(text, file.name)
        tags = read_gazebo_tags(root, warnings.append)
    except SimulationError as err:
        raise CheckError(what, f'the simulator refuses it: {err}',
                         'fix the tag it names') from None
    if not tags.diff_drives:
        raise CheckError(what, 'no <plugin name="gz::sim::systems::DiffDrive"> in a <gazebo> '
                         'tag', 'add <gazebo><plugin filename="gz-sim-diff-drive-system" '
                         'name="gz::sim::systems::DiffDrive"> … </plugin></gazebo>')
    drive = tags.diff_drives[0]
    wrong = _diff_drive_errors(robot, root, drive)
    if wrong:
        raise CheckError(what, *wrong)
    if not tags.lidars:
        raise CheckError(what, 'no <sensor type="gpu_lidar"> in a <gazebo reference="…"> tag',
                         'add <gazebo reference="laser_frame"><sensor name="lidar" '
                         'type="gpu_lidar"> … </sensor></gazebo>')
    lidar = tags.lidars[0]
    if lidar.link not in robot.links:
        raise CheckError(what, f'the lidar is on link {lidar.link!r}, which the robot does not '
                         f'have (links: {", ".join(robot.links)})',
                         'write the link\'s name in <gazebo reference="…">: laser_frame')
    if lidar.topic.strip('/') != lidar_topic:
        topic = lidar.topic or f'/world/<world>/model/<name>/link/{lidar.link}/sensor/…/scan'
        raise CheckError(what, f'the lidar publishes gz topic {topic}',
                         f'write <topic>{lidar_topic}</topic> in the sensor: the bridge (and '
                         f'this lesson) connects gz topic {lidar_topic} to /{lidar_topic}')
    if lidar.samples < 2 or lidar.max_angle <= lidar.min_angle:
        raise CheckError(what, f'the lidar has {lidar.samples} samples from {lidar.min_angle:g} '
                         f'to {lidar.max_angle:g} rad', 'give <horizontal> <samples>360'
                         '</samples>, <min_angle>-3.14159</min_angle> and <max_angle>3.14159'
                         '</max_angle>')
    passed(f'{file.name}: DiffDrive turns {drive.left_joints[0]} and {drive.right_joints[0]} '
           f'({drive.wheel_separation:g} m apart, radius {drive.wheel_radius:g} m) on '
           f'{drive.topic.strip("/")}/{drive.odom_topic.strip("/")}; a lidar on {lidar.link} '
           f'publishes {lidar_topic} ({lidar.samples} beams, {lidar.update_rate:g} Hz)')


_FAST_DDS = b'\x01\x0f'  # a GUID prefix's vendor id; bytes 4-5 hold its process's pid


def _process_alive(info: Any, running: set[int]) -> bool:
    """Whether an endpoint's participant still has a process: a bridge stopped a moment
    ago stays in the graph until its removal arrives (up to the DDS lease), and would
    answer for the one started after it."""
    prefix = bytes(info.endpoint_gid)[:12]
    if prefix[:2] != _FAST_DDS:
        return True  # another vendor: its prefix says nothing of its process
    return int.from_bytes(prefix[4:6], 'little') in running


def _endpoints(topic: str, publishers: bool) -> list[Any]:
    """The topic's publishers (or subscribers) of live processes, the kit's own left out."""
    from robot_lab.linux.procfs import pids
    from robot_lab.rclpy_session import session

    node = session().node
    found = (node.get_publishers_info_by_topic(topic) if publishers
             else node.get_subscriptions_info_by_topic(topic))
    running = {pid & 0xFFFF for pid in pids()}
    return [e for e in found
            if not e.node_name.startswith('_robot_lab') and _process_alive(e, running)]


def _bridge_fix(topic: str, ros_type: str, gz_type: str, direction: str) -> str:
    mark = ']' if direction == 'ROS_TO_GZ' else '['
    name = topic.strip('/')
    return (f'bridge it with: ros2 run ros_gz_bridge parameter_bridge '
            f'/{name}@{ros_type}{mark}{gz_type}, or in the bridge YAML: ros_topic_name: "{name}", '
            f'gz_topic_name: "{name}", ros_type_name: "{ros_type}", gz_type_name: '
            f'"{gz_type}", direction: {direction}')


@judged
def bridged(topics: dict[str, tuple[str, str, str]], timeout: float = 5.0) -> None:
    """Each ROS topic is connected to the simulation as named: `{topic: (ros_type,
    gz_type, 'GZ_TO_ROS' | 'ROS_TO_GZ')}`; GZ_TO_ROS topics carry messages."""
    from robot_lab.graph.topics import echo_stream
    from robot_lab.sim.control import bridge_hint
    from robot_lab.sim.xml_tree import SimulationError

    for topic, (ros_type, gz_type, direction) in topics.items():
        into_ros = direction == 'GZ_TO_ROS'
        what = (f'{topic} bridged from the simulation ({gz_type} → {ros_type})' if into_ros
                else f'{topic} bridged into the simulation ({ros_type} → {gz_type})')
        ends = wait_until(functools.partial(_endpoints, topic, into_ros), timeout)
        if not ends:
            other = _endpoints(topic, not into_ros)
            if other and not into_ros:
                seen = (f'{topic} is published by {other[0].node_name}, and nothing takes it '
                        'into the simulation')
                raise CheckError(what, seen, f'the bridge runs it the wrong way: direction '
                                 f'ROS_TO_GZ (or `]` on the command line): '
                                 f'{_bridge_fix(topic, ros_type, gz_type, direction)}')
            try:
                hint = bridge_hint(topic) if into_ros else None
            except SimulationError:
                raise CheckError(what, 'no simulation runs', 'run the launch cell above first '
                                 '(it starts the simulator and the bridge)') from None
            verb = 'publishes' if into_ros else 'subscribes to'
            seen = hint.split('; bridge it with: ')[0] if hint else f'nothing {verb} {topic}'
            raise CheckError(what, seen, _bridge_fix(topic, ros_type, gz_type, direction))
        kind = ends[0].topic_type
        if kind != ros_type:
            raise CheckError(what, f'{topic} carries {kind}',
                             f'ros_type_name: "{ros_type}" (and gz_type_name: "{gz_type}")')
        if into_ros:
            stream = echo_stream(topic, None, timeout=timeout)
            try:
                got = next(iter(stream), None)
            except Exception:  # a stream that fails to hear it: no message
                got = None
            finally:
                getattr(stream, 'close', lambda: None)()
            if got is None:
                raise CheckError(what, f'the bridge has {topic}, but no message came in '
                                 f'{timeout:g} s', f'check gz_topic_name: the simulator '
                                 f'publishes gz topic {topic.strip("/")} (!gz topic -l lists '
                                 'them)')
    passed('bridged: ' + ', '.join(
        f'{t} {"←" if d == "GZ_TO_ROS" else "→"} gz' for t, (_r, _g, d) in topics.items()))


class _ScanProbe:
    """Synthetic scans, shaped as the simulator's lidar sends them, to a controller in the
    kernel; what it answers on /cmd_vel."""

    SAMPLES = 360
    FAR = 4.0

    def __init__(self) -> None:
        from geometry_msgs.msg import Twist
        from sensor_msgs.msg import LaserScan

        from robot_lab.rclpy_session import session

        self.session = session()
        self.node = self.session.node
        self.scan_type = LaserScan
        self.publisher = self.node.create_publisher(LaserScan, '/scan', 10)
        self.lock = threading.Lock()
        self.replies: list[tuple[int, float]] = []
        self.sent = self.published = 0
        self.subscription = self.node.create_subscription(Twist, '/cmd_vel', self._on_cmd, 10)

    def _on_cmd(self, msg: Any) -> None:
        with self.lock:
            self.replies.append((self.sent, float(msg.linear.x)))

    def close(self) -> None:
        self.node.destroy_subscription(self.subscription)
        self.node.destroy_publisher(self.publisher)

    def scan(self, obstacle: float | None, at: float = 0.0) -> Any:
        """A full turn, −π to π, everything FAR except a 20° sector around `at` rad."""
        msg = self.scan_type()
        msg.header.frame_id = 'laser_frame'
        msg.angle_min, msg.angle_max = -math.pi, math.pi
        msg.angle_increment = 2 * math.pi / (self.SAMPLES - 1)
        msg.range_min, msg.range_max = 0.12, 10.0
        msg.scan_time = 0.1
        ranges = []
        for i in range(self.SAMPLES):
            angle = msg.angle_min + i * msg.angle_increment
            off = abs(math.atan2(math.sin(angle - at), math.cos(angle - at)))
            ranges.append(obstacle if obstacle is not None and off <= math.radians(10)
                          else self.FAR)
        msg.ranges = ranges
        return msg

    def speed(self, obstacle: float | None, at: float = 0.0, timeout: float = 3.0) -> float | None:
        """The controller's linear.x for this scan (None: it answered nothing)."""
        msg = self.scan(obstacle, at)
        with self.lock:
            self.sent += 1
            mark = self.sent
            # replies still to come for scans of the case before (the node answers each
            # scan once): they arrive under this mark, first; the ones after are this scan's
            stale = self.published - len(self.replies)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.lock:
                self.published += 1
            self.publisher.publish(msg)
            answer = wait_until(lambda: [v for s, v in self.replies if s == mark][stale:],
                                0.2, 0.02)
            if answer:
                return float(answer[-1])
        return None


def _scan_callback_failed(what: str) -> None:
    """callback_failed, with the hint for an index off the end of `ranges`: an angle
    taken in degrees, or an increment in degrees."""
    try:
        callback_failed(what)
    except CheckError as err:
        if 'IndexError' not in err.seen:
            raise
        raise CheckError(err.expected, err.seen, 'angle_min and angle_increment are in '
                         'radians: the beam at angle 0 is index (0 − angle_min) / '
                         'angle_increment, between 0 and len(ranges) − 1', err.details,
                         err.title) from None


def _angle_words(angle: float) -> str:
    degrees = round(math.degrees(angle))
    return {180: 'behind it (±180°)', 90: 'on its left (+90°)',
            -90: 'on its right (−90°)'}.get(degrees, f'at {degrees}°')


@judged
def reacts_to_scan(node: Any, target: float, gain: float, max_speed: float) -> None:
    """The controller in the kernel answers a scan with `gain × (distance ahead − target)`,
    within [0, max_speed]: full speed with nothing near, slower with an obstacle ahead,
    stopped at the target, and not fooled by an obstacle behind or beside it."""
    what = (f'/{node.get_name()} to drive at {gain:g} × (distance ahead − {target:g}) m/s, '
            f'between 0 and {max_speed:g}')
    _nothing_else_on_scan(what)
    probe = _ScanProbe()
    try:
        if not wait_until(lambda: _endpoints('/scan', False) and _endpoints('/cmd_vel', True),
                          5.0):
            _scan_callback_failed(what)
            raise CheckError(what, f'/{node.get_name()} does not subscribe to /scan and publish '
                             '/cmd_vel', 'keep the create_subscription and create_publisher '
                             'lines of the scaffold')
        cases = [(None, 0.0, max_speed), (target + 0.2, 0.0, gain * 0.2),
                 (target - 0.1, 0.0, 0.0), (target - 0.1, math.pi, max_speed)]
        for obstacle, at, expected in cases:
            got = probe.speed(obstacle, at)
            if got is None:
                _scan_callback_failed(what)
                raise CheckError(what, 'no /cmd_vel answered a scan in 3 s',
                                 'publish a Twist in on_scan, once per scan')
            expected = min(max_speed, max(0.0, expected))
            if abs(got - expected) <= 0.01 + 0.05 * expected:
                continue
            case = ('nothing within 4 m' if obstacle is None else
                    f'an obstacle {obstacle:g} m {"ahead" if at == 0.0 else _angle_words(at)}')
            if obstacle is not None and at == 0.0 and got > expected + 0.01:
                for probe_at in (math.pi, math.pi / 2, -math.pi / 2):
                    if (seen := probe.speed(obstacle, probe_at)) is not None and \
                            seen < got - 0.01:
                        raise CheckError(
                            what, f'it drives at {got:.2f} m/s with {case}, but slows to '
                            f'{seen:.2f} for one {_angle_words(probe_at)}',
                            'ranges[0] is the beam at angle_min (−π: behind the robot); the '
                            'beam straight ahead (angle 0) is ranges[round((0 − angle_min) / '
                            'angle_increment)], angles in radians')
            if got < -0.001:
                hint = 'never drive backwards: clamp the speed at 0 (max(0.0, …))'
            elif got > max_speed + 0.001:
                hint = f'clamp the speed at max_speed ({max_speed:g}): min(self.max_speed, …)'
            else:
                hint = 'speed = gain × (distance ahead − target_distance), clamped to ' \
                       '[0, max_speed]'
            raise CheckError(what, f'it drives at {got:.2f} m/s with {case} (expected '
                             f'{expected:.2f})', hint)
    finally:
        probe.close()
    passed(f'/{node.get_name()} slows for an obstacle ahead and stops {target:g} m before it; '
           'it ignores one behind')


class _Process:
    """A process a check starts, closed with the cell's run (robot_lab.notebook_cell)."""

    def __init__(self, cmd: list[str], env: dict[str, str]) -> None:
        from robot_lab.process import spawn

        self.proc = spawn(cmd, env=env)

    def close(self) -> None:
        from robot_lab.process import stop

        stop(self.proc, sigint_timeout=3.0, sigterm_timeout=2.0)


def _nothing_else_on_scan(what: str) -> None:
    """A check that sends its own scans (or runs its own world) needs /scan to itself: a
    simulation still running from earlier in the lesson would answer too."""
    if wait_until(lambda: not _endpoints('/scan', True), 3.0):
        return  # (a bridge just stopped takes a moment to leave the graph)
    others = sorted({e.node_name for e in _endpoints('/scan', True)})
    if others:
        raise CheckError(what, f'/{others[0]} publishes /scan already (a simulation still runs)',
                         'stop it first: system.shutdown() (the cell at the end of section 5), '
                         'then run this check again')


def _stop_hint(result: Any, gap: float) -> str:
    """What to try, for the first thing `judge_stop` found wrong."""
    if result.wiring_problem() is not None:
        return ("bridge /scan out of and /cmd_vel into the simulation (section 5's "
                "bridge.yaml), and keep your node's /scan subscription and /cmd_vel publisher")
    if result.collision:
        return ('the speed must fall to 0 at target_distance: check that ahead() reads the '
                'beam at angle 0, and that the speed is gain × (ahead − target), never above '
                'max_speed')
    if result.sim_time_problem() is not None:
        return ("give the Node parameters=[{'use_sim_time': True}] in stop_at_wall.launch.py")
    if not result.stopped:
        return 'the speed must reach 0: clamp it at 0 (max(0.0, …)) once ahead ≤ target'
    return (f'the lidar is 0.2 m behind the front of the robot: a target_distance of '
            f'{gap + 0.2:.2f} m leaves {gap:.2f} m to the wall')


@judged
def stops_before_obstacle(launch_file: str | Path, model: str | Path, bridge_yaml: str | Path,
                          gap: float = 0.3, tolerance: float = 0.05, wall: float = 1.5,
                          speed: float = 3.0) -> None:
    """In a world with a wall `wall` m ahead, the robot of `model` (its `<gazebo>` tags),
    bridged by `bridge_yaml`, driven by the nodes of `launch_file`, stops `gap` ±
    `tolerance` m before the wall (the simulator's ground truth: the gap between the
    collision shapes), touches nothing, and runs on the simulation's clock. The simulation
    runs at `speed` × real time (the controller reacts to each scan as it comes)."""
    import sys

    import robot_lab
    from robot_lab.errors import RobotLabError
    from robot_lab.notebook_cell import cell_owns
    from robot_lab.sim.trial import Trial, judge_stop, wall_ahead_sdf
    from robot_lab.sim.xml_tree import SimulationError

    launch, urdf, config = Path(launch_file), Path(model), Path(bridge_yaml)
    what = (f'your robot to stop {gap:g} ± {tolerance:g} m before a wall {wall:g} m ahead, '
            "without touching it, on the simulation's clock")
    _nothing_else_on_scan(what)
    text = _expand(urdf, what) if urdf.name.endswith('.xacro') else urdf.read_text()
    try:
        trial = Trial(wall_ahead_sdf(wall), text, obstacles=['wall'], name='my_robot',
                      bridge=False, speed=speed)
        trial.start()
    except SimulationError as err:
        raise CheckError(what, f'the simulator refused your robot: {err}',
                         'run the model through xacro and check_urdf (section 3)') from None
    cell_owns(trial)
    bridge = _Process([sys.executable, '-m', 'robot_lab.sim.bridge', '--ros-args', '-p',
                       f'config_file:={config}'], trial.env)
    cell_owns(bridge)
    try:
        try:
            controller = robot_lab.launch(launch)
        except RobotLabError as err:
            raise CheckError(what, f'{launch.name} does not start: {err}',
                             'fix the line it names, run that cell, then this one') from None
        result = trial.run(sim_seconds=15.0, wall_seconds=40.0, controller_timeout=15.0)
        ok, line = judge_stop(result, gap, tolerance, obstacle='the wall')
        if not ok:
            if not result.cmd_vel_publishers:
                tail = ' | '.join(controller.logs()[-3:]) or 'no output'
                line = f'{line}; your launch printed: {tail}'
            raise CheckError(what, line, _stop_hint(result, gap))
    finally:
        for thing in (locals().get('controller'), bridge, trial):
            if thing is not None:
                (thing.shutdown if hasattr(thing, 'shutdown') else thing.close)()
    passed(f'in a world with a wall {wall:g} m ahead, your robot stopped {gap:g} ± '
           f"{tolerance:g} m before it, touching nothing, on the simulation's clock")
