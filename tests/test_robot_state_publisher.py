"""robot_state_publisher and joint_state_publisher as real nodes: what they put on /tf,
/tf_static, /robot_description and /joint_states, checked against yourdfpy's forward
kinematics (an independent library) to 1e-9; and urdf_tutorial's display.launch.py."""

from __future__ import annotations

import math
import os
import random
import subprocess
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from builtin_interfaces.msg import Time
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosutil import set_param
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from test_urdf import BIN, MIMIC, MODELS, model_text, random_positions, reference
from tf2_msgs.msg import TFMessage

import robot_lab
from robot_lab.errors import GraphError
from robot_lab.rclpy_session import session
from robot_lab.urdf.joints import joint_table
from robot_lab.urdf.model import Robot, parse_urdf

LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


class Topic:
    """Every message of one topic the session node hears, with a wait on a condition."""

    def __init__(self, topic: str, kind: Any, qos: QoSProfile | int = 100) -> None:
        self.messages: list[Any] = []
        self._cond = threading.Condition()
        self._node = session().node
        self._sub = self._node.create_subscription(kind, topic, self._take, qos)
        self.topic = topic

    def _take(self, message: Any) -> None:
        with self._cond:
            self.messages.append(message)
            self._cond.notify_all()

    def wait_for(self, found: Callable[[Any], bool], what: str, timeout: float = 15.0) -> Any:
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                match = next((m for m in reversed(self.messages) if found(m)), None)
                if match is not None:
                    return match
                if not self._cond.wait(deadline - time.monotonic()):
                    raise AssertionError(f'{self.topic}: no {what} in {timeout} s; '
                                         f'{len(self.messages)} messages')

    def close(self) -> None:
        self._node.destroy_subscription(self._sub)


@pytest.fixture
def topics() -> Iterator[Callable[..., Topic]]:
    opened: list[Topic] = []

    def _open(topic: str, kind: Any, qos: QoSProfile | int = 100) -> Topic:
        opened.append(Topic(topic, kind, qos))
        return opened[-1]

    yield _open
    for topic in opened:
        topic.close()


def params_file(folder: Path, **values: Any) -> Path:
    """A parameter file: a URDF in a -p argument would be parsed as YAML by rcl."""
    path = folder / 'rsp.yaml'
    path.write_text(yaml.safe_dump({'/**': {'ros__parameters': values}}))
    return path


def pose_matrix(transform: Any) -> np.ndarray:
    t, q = transform.translation, transform.rotation
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), t.x],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), t.y],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), t.z],
        [0.0, 0.0, 0.0, 1.0]])


def compose(root: str, edges: dict[str, tuple[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Each frame's pose in `root` from child -> (parent, transform) edges."""
    poses = {root: np.eye(4)}
    while len(poses) <= len(edges):
        grown = {child: poses[parent] @ matrix for child, (parent, matrix) in edges.items()
                 if child not in poses and parent in poses}
        assert grown, f'frames not connected to {root}: {set(edges) - set(poses)}'
        poses.update(grown)
    return poses


def equal_to_yourdfpy(robot: Robot, ref: Any, prefix: str,
                      edges: dict[str, tuple[str, np.ndarray]],
                      positions: dict[str, float]) -> None:
    """The frames composed from the messages' edges are yourdfpy's link poses (1e-9)."""
    poses = compose(prefix + robot.root, edges)
    ref.update_cfg(positions)
    for link in robot.links:
        expected = ref.get_transform(link, robot.root)
        assert np.abs(poses[prefix + link] - expected).max() < 1e-9, link


@pytest.mark.parametrize(('model', 'prefix'), [
    *((name, '') for name in MODELS[:5]),  # fixed joints only: /tf_static alone
    ('06-flexible.urdf', ''), ('07-physics.urdf', 'bot/'), ('08-macroed.urdf.xacro', 'r2/'),
    ('mimic', 'g/')])
def test_tf_and_tf_static_equal_yourdfpy(start: Any, tmp_path: Path, topics: Any,
                                         model: str, prefix: str) -> None:
    """urdf_tutorial 01–08 (each through xacro, as urdf_launch loads them) and a mimic
    joint: what the node sends, composed, is yourdfpy's forward kinematics."""
    text = MIMIC if model == 'mimic' else model_text(model)
    robot = parse_urdf(text)
    node = start('ros2', 'run', 'robot_state_publisher', 'robot_state_publisher',
                 '--ros-args', '--params-file',
                 str(params_file(tmp_path, robot_description=text, frame_prefix=prefix)))
    node.wait_for(r'\[robot_state_publisher\]: Robot initialized')
    # Subscribed after the node published them once: transient-local, as upstream's.
    description = topics('/robot_description', String, LATCHED)
    assert description.wait_for(lambda m: True, 'description').data == text
    static = topics('/tf_static', TFMessage, LATCHED).wait_for(lambda m: True, 'static')
    fixed = [j for j in robot.joints.values() if j.type == 'fixed']
    assert sorted(t.child_frame_id for t in static.transforms) == sorted(
        prefix + j.child for j in fixed)
    edges = {t.child_frame_id: (t.header.frame_id, pose_matrix(t.transform))
             for t in static.transforms}
    ref = reference(text)
    moving = sorted(prefix + j.child for j in robot.joints.values() if j.moves)
    if not moving:
        equal_to_yourdfpy(robot, ref, prefix, edges, {})
        return

    tf = topics('/tf', TFMessage)
    states = session().node.create_publisher(JointState, '/joint_states', 10)
    rng = random.Random(model)
    try:
        for second in range(1, 6):  # stamps 1 s apart: past the 20 Hz limit per joint
            positions = random_positions(robot, rng)
            stamp = Time(sec=1_000 + second)
            message = JointState(name=list(positions), position=list(positions.values()))
            message.header.stamp = stamp

            def sent(m: Any, stamp: Any = stamp) -> bool:
                return bool(m.transforms) and m.transforms[0].header.stamp == stamp

            deadline = time.monotonic() + 15
            while True:  # resent until heard: the first may precede the match
                states.publish(message)
                try:
                    moved = tf.wait_for(sent, f'/tf stamped {stamp.sec}', timeout=0.5)
                    break
                except AssertionError:
                    if time.monotonic() > deadline:
                        raise
            # every moving joint, mimic ones from their leader, once, at the state's stamp
            assert sorted(t.child_frame_id for t in moved.transforms) == moving
            assert all(t.header.stamp == stamp for t in moved.transforms)
            equal_to_yourdfpy(robot, ref, prefix, {
                **edges, **{t.child_frame_id: (t.header.frame_id, pose_matrix(t.transform))
                            for t in moved.transforms}}, positions)
    finally:
        session().node.destroy_publisher(states)


def test_a_new_robot_description_is_published_and_a_bad_one_refused(
        start: Any, tmp_path: Path, topics: Any) -> None:
    """`ros2 param set` of robot_description: read again, latched again, its fixed joints
    sent again; an unreadable one is refused with the line and the fix, as the reason."""
    node = start('ros2', 'run', 'robot_state_publisher', 'robot_state_publisher',
                 '--ros-args', '--params-file',
                 str(params_file(tmp_path, robot_description=MIMIC)))
    node.wait_for(r'Robot initialized')
    other = model_text('03-origins.urdf')
    assert set_param('/robot_state_publisher', 'robot_description', other) == (True, '')
    description = topics('/robot_description', String, LATCHED)
    assert description.wait_for(lambda m: m.data == other, 'the new description').data
    static = topics('/tf_static', TFMessage, LATCHED).wait_for(
        lambda m: 'right_leg' in {t.child_frame_id for t in m.transforms}, 'its fixed joint')
    assert {t.child_frame_id for t in static.transforms} == {'right_leg'}  # MIMIC: none
    ok, reason = set_param('/robot_state_publisher', 'robot_description',
                           other.replace('<link name="right_leg">', '<link name="rite_leg">'))
    assert not ok and reason.startswith('robot_description:') and (
        "joint 'base_to_right_leg' names child link 'right_leg', which no <link> defines — "
        "fix: did you mean 'rite_leg'?") in reason
    assert set_param('/robot_state_publisher', 'robot_description', '') == (
        False, 'Empty URDF is not allowed')


def test_joint_state_publisher_feeds_robot_state_publisher(start: Any, tmp_path: Path,
                                                           topics: Any) -> None:
    """zeros.<joint>, source_list and the URDF from /robot_description, as upstream's."""
    text = model_text('08-macroed.urdf.xacro')
    robot = parse_urdf(text)
    joint_states = topics('/joint_states', JointState)
    start('ros2', 'run', 'robot_state_publisher', 'robot_state_publisher', '--ros-args',
          '--params-file', str(params_file(tmp_path, robot_description=text)))
    start('ros2', 'run', 'joint_state_publisher', 'joint_state_publisher', '--ros-args',
          '-p', 'zeros.head_swivel:=0.5', '-p', "source_list:=['/slider_states']")
    first = joint_states.wait_for(lambda m: True, 'joint states')
    assert list(first.name) == joint_table(robot).order  # the URDF's order
    assert dict(zip(first.name, first.position, strict=True)) == {
        name: 0.5 if name == 'head_swivel' else 0.0 for name in first.name}

    sliders = session().node.create_publisher(JointState, '/slider_states', 10)
    tf = topics('/tf', TFMessage)
    try:
        def moved(m: Any) -> bool:
            return dict(zip(m.name, m.position, strict=True)).get('gripper_extension') == -0.25

        deadline = time.monotonic() + 15
        while True:  # a source's message counts once heard; resent until it is
            sliders.publish(JointState(name=['gripper_extension'], position=[-0.25]))
            try:
                joint_states.wait_for(moved, 'the source_list value', timeout=0.5)
                break
            except AssertionError:
                if time.monotonic() > deadline:
                    raise
        pole = tf.wait_for(lambda m: any(t.child_frame_id == 'gripper_pole' and
                                         abs(t.transform.translation.x + 0.06) < 1e-9
                                         for t in m.transforms), 'the pole moved')
        assert {t.child_frame_id for t in pole.transforms} >= {'gripper_pole', 'head'}
    finally:
        session().node.destroy_publisher(sliders)


def test_a_bad_urdf_is_one_line_naming_its_line(start: Any, tmp_path: Path) -> None:
    text = MIMIC.replace('<parent link="finger_b"/>', '<parent link="finger_c"/>')
    node = start('ros2', 'run', 'robot_state_publisher', 'robot_state_publisher', '--ros-args',
                 '--params-file', str(params_file(tmp_path, robot_description=text)))
    assert node.popen.wait(timeout=30) == 1
    line = next(n for n, row in enumerate(text.splitlines(), 1) if 'name="s"' in row)
    assert node.lines[-1] == (
        f"[FATAL] [robot_state_publisher]: robot_description:{line}: joint 's' names parent "
        "link 'finger_c', which no <link> defines — fix: did you mean 'finger_a'? name an "
        'existing link, or add <link name="finger_c"/>')
    assert not any('Traceback' in row for row in node.lines)


def test_ros2_run_xacro_is_the_venvs_xacro(tmp_path: Path) -> None:
    """As the pages also write it: `ros2 run xacro xacro`, $(find) through the kit's index
    even with AMENT_PREFIX_PATH unset (a module with a domain: `ros2 run` reads it)."""
    source = tmp_path / 'include.urdf.xacro'
    source.write_text('<robot name="i" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                      '<xacro:include filename="$(find urdf_tutorial)/urdf/01-myfirst.urdf"/>'
                      '</robot>')
    env = {k: v for k, v in os.environ.items() if k != 'AMENT_PREFIX_PATH'}
    runs = [subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
            for cmd in ([str(BIN / 'ros2'), 'run', 'xacro', 'xacro', str(source)],
                        [str(BIN / 'xacro'), str(source)])]
    assert all(run.returncode == 0 for run in runs), [run.stderr for run in runs]
    assert runs[0].stdout == runs[1].stdout and '<link name="base_link">' in runs[0].stdout


def test_display_launch_runs_the_publishers_and_the_sliders_move_the_robot(
        start: Any, topics: Any) -> None:
    """urdf_tutorial's launch line, then the notebook's two: the sliders (feeding the
    launch's joint_state_publisher, not publishing beside it) move a link on /tf."""
    tf = topics('/tf', TFMessage)
    launch = start('ros2', 'launch', 'urdf_tutorial', 'display.launch.py',
                   'model:=urdf/08-macroed.urdf.xacro')
    launch.wait_for(r"\[INFO\] \[launch.user\]: RViz's view, in a notebook: "
                    r"robot_lab\.scene_view\(fixed_frame='base_link'\)$", timeout=30)
    launch.wait_for(r'robot_lab\.joint_sliders\(\)$')
    message = tf.wait_for(lambda m: len(m.transforms) == 8, 'the 8 moving joints', 30)
    assert {t.header.frame_id for t in message.transforms} >= {'base_link'}

    sliders = robot_lab.joint_sliders()  # the URDF from /robot_description
    try:
        assert sliders.robot.name == 'macroed' and len(sliders.widget.children) == 8 + 3
        feed = sliders._feed
        assert feed is not None
        deadline = time.monotonic() + 15  # the launch's joint_state_publisher matched
        while feed.get_subscription_count() != 1:
            assert time.monotonic() < deadline, 'joint_state_publisher never took the feed'
            time.sleep(0.05)
        assert sliders.set('gripper_extension', -1.0) == -0.38  # held at <limit lower>
        tf.wait_for(lambda m: any(t.child_frame_id == 'gripper_pole' and
                                  abs(t.transform.translation.x - (0.19 - 0.38)) < 1e-9
                                  for t in m.transforms), 'the pole moved by the slider')
    finally:
        sliders.close()


def test_sliders_alone_publish_joint_states_within_the_limits(topics: Any) -> None:
    """Without a joint_state_publisher: /joint_states from the sliders, continuous joints
    over ±π, mimic joints from their leader; a moved slider is the next message."""
    text = MIMIC.replace('type="revolute">\n    <parent link="base"/><child link="finger_a"/>',
                         'type="continuous">\n    <parent link="base"/><child link="finger_a"/>')
    assert text != MIMIC
    joint_states = topics('/joint_states', JointState)
    sliders = robot_lab.joint_sliders(robot_description=text, rate=20.0)
    try:
        rows = {w.description: w for w in sliders.widget.children
                if hasattr(w, 'max') and hasattr(w, 'description')}
        assert set(rows) == {'a', 's'}  # b mimics a: no slider
        assert (rows['a'].min, rows['a'].max) == (-math.pi, math.pi)
        assert (rows['s'].min, rows['s'].max) == (0.05, 0.1)  # the soft limits
        rows['a'].value = 1.0  # as a drag in the browser sets it
        heard = joint_states.wait_for(
            lambda m: list(m.position[:2]) == [1.0, 1.0 * -1.5 + 0.25], 'the slider value')
        assert list(heard.name) == ['a', 'b', 's'] and heard.position[2] == pytest.approx(0.075)
        assert sliders.set('s', 5.0) == 0.1 and rows['s'].value == 0.1
        with pytest.raises(GraphError, match="'b' is not a joint a slider moves"):
            sliders.set('b', 0.0)
    finally:
        sliders.close()


class Sent:
    """Stands in for the node's /tf publisher: keeps what it would have sent."""

    def __init__(self) -> None:
        self.messages: list[TFMessage] = []

    def publish(self, message: TFMessage) -> None:
        self.messages.append(message)


def state(stamp_ns: int, **positions: float) -> JointState:
    message = JointState(name=list(positions), position=list(positions.values()))
    message.header.stamp = Time(sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    return message


@pytest.mark.parametrize('ignore_timestamp', [False, True])
def test_publish_frequency_limits_each_joint_by_its_stamps(ignore_timestamp: bool) -> None:
    """Upstream's rule: a joint's transform goes out again only once the message's stamp
    is 1/publish_frequency past the last one sent for the least recent of its joints
    (ignore_timestamp: every message); a malformed message is dropped."""
    from rclpy.parameter import Parameter

    from robot_lab.urdf.state_publisher import RobotStatePublisher

    node = RobotStatePublisher(context=session().context, parameter_overrides=[
        Parameter('robot_description', value=MIMIC),
        Parameter('ignore_timestamp', value=ignore_timestamp),
        Parameter('frame_prefix', value='p/')])
    try:
        sent = Sent()
        node.tf = sent  # type: ignore[assignment]
        base = 5 * 10**9
        node.on_joint_state(state(base, a=0.1))  # new joints: always sent
        node.on_joint_state(state(base + 49_000_000, a=0.2))  # < 50 ms (20 Hz) later
        node.on_joint_state(state(base + 50_000_000, a=0.3))
        node.on_joint_state(state(base + 60_000_000, s=0.07))  # s is new: sent
        bad = state(base + 10**9, a=0.1, s=0.1)
        bad.position = [0.1]
        node.on_joint_state(bad)
        children = [sorted(t.child_frame_id for t in m.transforms) for m in sent.messages]
        expected_a = ['p/finger_a', 'p/finger_b']  # b mimics a
        if ignore_timestamp:
            assert children == [expected_a] * 3 + [['p/slider']]
        else:
            assert children == [expected_a] * 2 + [['p/slider']]
            assert [m.transforms[0].header.stamp.nanosec for m in sent.messages] == [
                0, 50_000_000, 60_000_000]
    finally:
        node.destroy_node()
