"""Lesson 12's checks (robot_lab.grading.check.description): the right answer passes, and
each mistake of the chapter gets its own message: a wrong parent link, a revolute joint
without limits, a quaternion that is not unit length (or built from the whole angle, or
none), a stamp from the past, a lookup before the transform exists, a point in the wrong frame.

The URDF and xacro checks read files (no ROS); the tf2 ones run real nodes in this
process's session, on the module's own domain.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import rclpy
from geometry_msgs.msg import PointStamped, TransformStamped
from rclpy.node import Node

from robot_lab.grading import CheckError, check

VENV_BIN = Path(__file__).resolve().parents[1] / '.venv' / 'bin'

WHEEL = """
  <link name="{side}_wheel"><visual><origin rpy="1.5708 0 0"/>
    <geometry><cylinder radius="0.08" length="0.04"/></geometry></visual></link>
  <joint name="{side}_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="{side}_wheel"/>
    <origin xyz="0.1 {y} -0.02"/><axis xyz="0 1 0"/>
  </joint>"""
REST = """
  <link name="caster"><visual><geometry><sphere radius="0.05"/></geometry></visual></link>
  <joint name="caster_joint" type="fixed">
    <parent link="base_link"/><child link="caster"/><origin xyz="-0.15 0 -0.05"/>
  </joint>
  <link name="temp_sensor_link"/>
  <joint name="temp_sensor_joint" type="fixed">
    <parent link="base_link"/><child link="temp_sensor_link"/><origin xyz="0.15 0 0.07"/>
  </joint>"""
BASE = '<link name="base_link"><visual><geometry><box size="0.4 0.3 0.1"/></geometry>' \
       '</visual></link>'
ROBOT = (f'<?xml version="1.0"?>\n<robot name="my_robot">\n  {BASE}'
         + WHEEL.format(side='left', y='0.175') + WHEEL.format(side='right', y='-0.175')
         + REST + '\n</robot>\n')
MACRO = ('<xacro:macro name="wheel" params="side y">'
         + WHEEL.replace('{side}', '${side}').replace('{y}', '${y}') + '\n</xacro:macro>')
XACRO = ('<?xml version="1.0"?>\n<robot name="my_robot" '
         'xmlns:xacro="http://www.ros.org/wiki/xacro">\n  ' + BASE + MACRO
         + '\n<xacro:wheel side="left" y="0.175"/>\n<xacro:wheel side="right" y="-0.175"/>'
         + REST + '\n</robot>\n')
PARENTS = {'left_wheel': 'base_link', 'right_wheel': 'base_link', 'caster': 'base_link',
           'temp_sensor_link': 'base_link'}
TYPES = {'left_wheel_joint': 'continuous', 'right_wheel_joint': 'continuous',
         'caster_joint': 'fixed', 'temp_sensor_joint': 'fixed'}


def _file(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _caster_on(text: str) -> str:
    return text.replace('<parent link="base_link"/><child link="caster"/>',
                        '<parent link="left_wheel"/><child link="caster"/>')


@pytest.mark.no_ros
def test_the_lessons_robot_passes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    check.urdf_tree(_file(tmp_path, 'my_robot.urdf', ROBOT), PARENTS, TYPES)
    assert capsys.readouterr().out == (
        '✓ my_robot.urdf: base_link carries left_wheel, right_wheel, caster, '
        'temp_sensor_link; left_wheel_joint, right_wheel_joint turn\n')


@pytest.mark.no_ros
@pytest.mark.parametrize(('mistake', 'edit', 'says'), [
    ('the caster on a wheel', _caster_on,
     r"observed caster's parent link is 'left_wheel' \(joint 'caster_joint', line \d+\)\. "
     r'Try: in joint .caster_joint., write <parent link="base_link"/>'),
    ('a revolute wheel without limits',
     lambda t: t.replace('"left_wheel_joint" type="continuous"', '"left_wheel_joint" '
                         'type="revolute"'),
     r"check_urdf refuses it: line \d+: joint 'left_wheel_joint' is revolute but has no "
     r'<limit>.*Try: add <limit lower='),
    ('a revolute wheel with limits',
     lambda t: t.replace('"left_wheel_joint" type="continuous">', '"left_wheel_joint" '
                         'type="revolute"><limit lower="-1" upper="1" effort="1" '
                         'velocity="1"/>'),
     r"joint 'left_wheel_joint' is revolute .*Try: make it type=\"continuous\""),
    ('a misspelt parent', lambda t: t.replace('<parent link="base_link"/><child link="caster"/>',
                                              '<parent link="base"/><child link="caster"/>'),
     r"names parent link 'base', which no <link> defines\. Try: did you mean 'base_link'"),
    ('no sensor link', lambda t: t.replace('<link name="temp_sensor_link"/>', ''),
     r"names child link 'temp_sensor_link', which no <link> defines"),
])
def test_each_urdf_mistake_is_named(tmp_path: Path, mistake: str, edit: Callable[[str], str],
                                    says: str) -> None:
    path = _file(tmp_path, 'my_robot.urdf', edit(ROBOT))
    with pytest.raises(CheckError, match=says):
        check.urdf_tree(path, PARENTS, TYPES)


@pytest.fixture
def venv_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """The lesson's first cell puts the venv's bin/ (xacro) on PATH."""
    monkeypatch.setenv('PATH', f'{VENV_BIN}{os.pathsep}{os.environ.get("PATH", "")}')


@pytest.mark.no_ros
@pytest.mark.usefixtures('venv_path')
@pytest.mark.parametrize(('mistake', 'edit', 'says'), [
    ('right', lambda t: t, None),
    ('called once', lambda t: t.replace('<xacro:wheel side="right" y="-0.175"/>', ''),
     r'observed the macro is called 1 time\(s\)\. Try: call it once per wheel'),
    ('both wheels on one side', lambda t: t.replace('y="-0.175"', 'y="0.175"'),
     r"joint 'right_wheel_joint' differs from my_robot\.urdf"),
    ('no macro', lambda t: t.replace('name="wheel"', 'name="tyre"'),
     r'observed no <xacro:macro name="wheel">'),
    ('a parameter misspelt', lambda t: t.replace('link name="${side}_wheel"',
                                                 'link name="${sde}_wheel"'),
     r"observed xacro failed: name 'sde' is not defined"),
])
def test_xacro_twin_and_its_mistakes(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                     mistake: str, edit: Callable[[str], str],
                                     says: str | None) -> None:
    urdf = _file(tmp_path, 'my_robot.urdf', ROBOT)
    twin = _file(tmp_path, 'my_robot.urdf.xacro', edit(XACRO))
    if says is None:
        check.xacro_expands(twin, like=urdf, macro='wheel')
        assert 'expands to 5 links and 4 joints' in capsys.readouterr().out
    else:
        with pytest.raises(CheckError, match=says):
            check.xacro_expands(twin, like=urdf, macro='wheel')


# --- tf2: real nodes in this process's session --------------------------------------------

@pytest.fixture
def spin() -> Iterator[Callable[[Node], Node]]:
    """Add nodes to the kernel-like session; every one is removed and destroyed after."""
    from robot_lab.rclpy_session import session

    nodes: list[Node] = []

    def add(node: Node) -> Node:
        session().add_node(node)
        nodes.append(node)
        return node

    yield add
    for node in nodes:
        session().remove_node(node)
        node.destroy_node()
    session().callback_errors.clear()


def _context() -> Any:
    from robot_lab.rclpy_session import session

    return session().context


class Odometry(Node):
    """The lesson's broadcaster (a 1 m circle at 0.5 rad/s), with one mistake or none."""

    def __init__(self, mistake: str) -> None:
        super().__init__(f'odom_{mistake}', context=_context())
        from robot_lab.tf2.broadcasters import TransformBroadcaster

        self.mistake = mistake
        self.broadcaster = TransformBroadcaster(self)
        self.x = self.y = self.yaw = 0.0
        self.start = self.get_clock().now()
        self.timer = self.create_timer(0.05, self.on_timer)

    def on_timer(self) -> None:
        self.yaw += 0.5 * 0.05
        self.x += 0.5 * 0.05 * math.cos(self.yaw)
        self.y += 0.5 * 0.05 * math.sin(self.yaw)
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = 'odom', 'base_link'
        t.transform.translation.x, t.transform.translation.y = self.x, self.y
        now = self.get_clock().now()
        t.header.stamp = (now - rclpy.duration.Duration(seconds=30) if self.mistake == 'old_stamp'
                          else self.start if self.mistake == 'fixed_stamp' else now).to_msg()
        half = self.yaw if self.mistake == 'whole_angle' else self.yaw / 2
        if self.mistake == 'only_z':  # w keeps its default, 1
            t.transform.rotation.z = math.sin(half)
        elif self.mistake != 'no_rotation':
            t.transform.rotation.z, t.transform.rotation.w = math.sin(half), math.cos(half)
        self.broadcaster.sendTransform(t)


@pytest.mark.parametrize(('mistake', 'says'), [
    ('only_z', r'rotation \(x, y, z, w\) = \(0, 0, 0\.\d+, 1\), length 1\.\d+: tf2 refuses it '
               r'\(TF_DENORMALIZED_QUATERNION\)\. Try: .*z = sin\(yaw / 2\).*set w too'),
    ('whole_angle', r'base_link faces \d+° away from the way it moves\. Try: .*half the angle'),
    ('no_rotation', r'base_link faces \d+° away from the way it moves\. Try: .*no turn'),
    ('fixed_stamp', r'observed every transform carries the same stamp \(\d+\.\d+ s\).*'
                    r'TF_OLD_DATA.*Try: stamp each transform as you send it'),
    ('old_stamp', r'a stamp 30\.\d s old .*TF_OLD_DATA.*Try: stamp each transform as you send '
                  r'it: t\.header\.stamp = self\.get_clock\(\)\.now\(\)\.to_msg\(\)'),
    ('none', None),
])
def test_a_broadcasters_mistakes_are_named(spin: Callable[[Node], Node], mistake: str,
                                           says: str | None,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    spin(Odometry(mistake))
    if says is None:
        check.transform_broadcast('odom', 'base_link', timeout=10)
        assert 'facing the way it drives' in capsys.readouterr().out
    else:
        with pytest.raises(CheckError, match=says):
            check.transform_broadcast('odom', 'base_link', timeout=10)


@pytest.mark.no_ros
@pytest.mark.parametrize(('roll', 'pitch'), [(0.0, 0.0), (0.3, 0.0), (0.3, 0.2), (0.6, 0.5)])
@pytest.mark.parametrize('yaw', [1.0, -2.5, 3.0])
def test_the_heading_is_the_yaw_even_when_the_base_tilts(roll: float, pitch: float,
                                                         yaw: float) -> None:
    """A base on a slope (roll and pitch) faces its yaw, as tf2_echo prints it; the planar
    2·atan2(z, w) is 0.16 rad off at roll 0.6, pitch 0.5."""
    from geometry_msgs.msg import Quaternion

    from robot_lab.grading.check.description import _yaw
    from robot_lab.tf2.linear_math import quaternion_from_euler

    x, y, z, w = quaternion_from_euler(roll, pitch, yaw)
    assert _yaw(Quaternion(x=x, y=y, z=z, w=w)) == pytest.approx(yaw, abs=1e-9)


def _static(parent: str, child: str, x: float, z: float) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.z = x, z
    t.transform.rotation.w = 1.0
    return t


class Locator(Node):
    """A student's listener: the sensor's origin in odom on a timer, one mistake or none."""

    def __init__(self, mistake: str) -> None:
        super().__init__(f'locate_{mistake}', context=_context())
        from robot_lab.tf2.buffer import Buffer
        from robot_lab.tf2.listener import TransformListener

        self.mistake = mistake
        self.tf_buffer = Buffer()
        self.listener = TransformListener(self.tf_buffer, self)
        self.pub = self.create_publisher(PointStamped, '/sensor/temperature_location', 10)
        self.timer = self.create_timer(0.1, self.on_timer)

    def on_timer(self) -> None:
        if self.mistake == 'too_soon':  # a frame nobody broadcasts: "does not exist"
            self.tf_buffer.lookup_transform('odom', 'no_such_link', rclpy.time.Time())
        target, source = ('temp_sensor_link', 'odom') if self.mistake == 'inverted' else \
            ('odom', 'temp_sensor_link')
        try:
            t = self.tf_buffer.lookup_transform(target, source, rclpy.time.Time())
        except Exception:
            return
        point = PointStamped()
        point.header.stamp = t.header.stamp
        point.header.frame_id = 'base_link' if self.mistake == 'frame' else 'odom'
        point.point.x = t.transform.translation.x
        point.point.y = t.transform.translation.y
        point.point.z = t.transform.translation.z
        self.pub.publish(point)


@pytest.mark.parametrize(('mistake', 'says'), [
    ('too_soon', r'your callback on_timer\(\) raised LookupException: .*does not exist.* '
                 r'Try: .*catch tf2_ros\.TransformException.*timeout='),
    ('frame', r"observed header\.frame_id 'base_link'\. Try: the point is in odom"),
    ('inverted', r'observed \(-1\.150, 0\.000, -0\.170\); tf2 puts temp_sensor_link at '
                 r"\(1\.150, 0\.000, 0\.170\)\. Try: lookup_transform\('odom', "),
    ('none', None),
])
def test_a_listeners_mistakes_are_named(spin: Callable[[Node], Node], mistake: str,
                                        says: str | None,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    from robot_lab.tf2.broadcasters import StaticTransformBroadcaster

    frames = spin(Node('frames', context=_context()))
    statics = StaticTransformBroadcaster(frames)
    statics.sendTransform([_static('odom', 'base_link', 1.0, 0.1),
                           _static('base_link', 'temp_sensor_link', 0.15, 0.07)])
    spin(Locator(mistake))
    if says is None:
        check.point_in_frame('/sensor/temperature_location', 'odom', 'temp_sensor_link')
        assert 'as tf2 places it' in capsys.readouterr().out
    else:
        with pytest.raises(CheckError, match=says):
            check.point_in_frame('/sensor/temperature_location', 'odom', 'temp_sensor_link',
                                 timeout=2)


# --- the package grader's optional rubric lines (grading/package/checks/description) ------

RUBRIC_LINES = """
  - id: urdf_describes
    name: The URDF describes the robot
    points: 2
    links: [base_link, left_wheel, right_wheel, caster, temp_sensor_link]
    parents: {left_wheel: base_link, right_wheel: base_link, caster: base_link,
              temp_sensor_link: base_link}
    joints: {left_wheel_joint: continuous, right_wheel_joint: continuous,
             caster_joint: fixed, temp_sensor_joint: fixed}
  - id: tf_tree
    name: robot_state_publisher publishes the robot's TF tree
    points: 1
"""


def _graded(tmp_path: Path, files: dict[str, str]) -> Any:
    """A job's state for a description package holding `files`, under the shipped
    ch6-lab1 rubric with its commented optional lines switched on."""
    from robot_lab.grading.package.rubric import load_rubric, rubric_path
    from robot_lab.grading.package.state import JobState

    shipped = rubric_path('ch6-lab1').read_text()
    assert '# - id: urdf_describes' in shipped and '# - id: tf_tree' in shipped
    rubric = _file(tmp_path, 'rubric.yaml', shipped + RUBRIC_LINES)
    package = tmp_path / 'my_robot_description'
    for rel, text in files.items():
        (package / rel).parent.mkdir(parents=True, exist_ok=True)
        (package / rel).write_text(text)
    return JobState(load_rubric(rubric), package=package, package_name=package.name)


def _verdict(state: Any, check_id: str) -> Any:
    from robot_lab.grading.package.registry import registered_checks

    return registered_checks()[check_id].run(state, state.rubric.check(check_id))


@pytest.mark.no_ros
@pytest.mark.usefixtures('venv_path')
@pytest.mark.parametrize(('files', 'earned', 'says'), [
    ({'urdf/my_robot.urdf': ROBOT}, True, r'`urdf/my_robot\.urdf`: robot `my_robot`, root '
                                          r'`base_link`, 5 links, 4 joints$'),
    ({'urdf/my_robot.urdf.xacro': XACRO}, True, r'`urdf/my_robot\.urdf\.xacro`: .* 5 links'),
    ({'urdf/my_robot.urdf': _caster_on(ROBOT)}, False,
     r'`caster` has parent `left_wheel` \(joint `caster_joint`, line \d+\), not `base_link`'),
    ({'urdf/my_robot.urdf': ROBOT.replace('type="continuous"', 'type="revolute"')}, False,
     r"check_urdf refuses it: urdf/my_robot\.urdf:\d+: joint 'left_wheel_joint' is revolute "
     r'but has no <limit>'),
    ({'setup.py': ''}, False, r'no \.urdf or \.xacro file in `my_robot_description/`'),
])
def test_the_package_grader_reads_a_description(tmp_path: Path, files: dict[str, str],
                                                earned: bool, says: str) -> None:
    verdict = _verdict(_graded(tmp_path, files), 'urdf_describes')
    assert verdict.earned is earned
    assert re.search(says, verdict.observed), verdict.observed


@pytest.mark.no_ros
@pytest.mark.parametrize(('topics', 'earned', 'says'), [
    ({'/robot_description': [], '/tf_static': [],
      '/tf': [('base_link', 'left_wheel'), ('base_link', 'right_wheel')]}, True,
     r'/tf carries 2 moving joint\(s\)'),
    ({'/robot_description': [], '/tf_static': [], '/tf': [('base_link', 'left_wheel')]}, False,
     r'/tf never carried base_link → right_wheel'),
    ({'/tf': [('base_link', 'left_wheel'), ('base_link', 'right_wheel')]}, False,
     r'nobody publishes /robot_description.*nobody publishes /tf_static'),
])
def test_the_package_grader_reads_the_tf_tree(tmp_path: Path, topics: dict[str, Any],
                                              earned: bool, says: str) -> None:
    from robot_lab.grading.package.roles import Observation, Roles, TopicSeen

    state = _graded(tmp_path, {'urdf/my_robot.urdf': ROBOT})
    obs = Observation()
    for name, edges in topics.items():
        seen = obs.topics[name] = TopicSeen(name, ['t'], publishers=['/robot_state_publisher'])
        seen.values.extend({'transforms': [{'header': {'frame_id': p}, 'child_frame_id': c}]}
                           for p, c in edges)
    state.live.obs, state.live.roles = obs, Roles()
    verdict = _verdict(state, 'tf_tree')
    assert verdict.earned is earned
    assert re.search(says, verdict.observed), verdict.observed
