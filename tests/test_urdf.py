"""robot_lab.urdf against an independent library: forward kinematics equal to yourdfpy's
to 1e-9 on urdf_tutorial 01–08 at random joint positions; errors that name the line and
the fix; check_urdf's output; xacro's `$(find pkg)` through the kit's ament index."""

from __future__ import annotations

import io
import math
import os
import random
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yourdfpy

from robot_lab.errors import UrdfError
from robot_lab.urdf.joints import joint_table
from robot_lab.urdf.kinematics import link_poses, quaternion, rpy_matrix
from robot_lab.urdf.model import Robot, parse_urdf

pytestmark = pytest.mark.no_ros  # files and subprocesses that start no ROS node

BIN = Path(sys.executable).parent
SHARE = Path(sys.prefix) / 'share' / 'urdf_tutorial'
MODELS = ['01-myfirst.urdf', '02-multipleshapes.urdf', '03-origins.urdf',
          '04-materials.urdf', '05-visual.urdf', '06-flexible.urdf', '07-physics.urdf',
          '08-macroed.urdf.xacro']


def model_text(name: str) -> str:
    """The model as robot_state_publisher gets it: through the venv's xacro, as
    urdf_launch's description.launch.py passes every model (plain URDF included)."""
    return subprocess.run([str(BIN / 'xacro'), str(SHARE / 'urdf' / name)], check=True,
                          capture_output=True, text=True).stdout


def random_positions(robot: Robot, rng: random.Random) -> dict[str, float]:
    """Each free joint (not mimic) anywhere in its range; continuous ones beyond ±π."""
    positions = {}
    for name, joint in joint_table(robot).free.items():
        low, high = (-4.0, 4.0) if joint.continuous else (joint.lower, joint.upper)
        positions[name] = rng.uniform(low, high)
    return positions


def reference(text: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(io.StringIO(text), load_meshes=False, build_scene_graph=True,
                              filename_handler=lambda name: name)


def largest_difference(robot: Robot, ref: yourdfpy.URDF,
                       positions: dict[str, float]) -> float:
    ref.update_cfg(positions)
    ours = link_poses(robot, positions)
    assert set(ours) == set(ref.link_map)
    return max(float(np.abs(np.array(pose.matrix()) - ref.get_transform(link, robot.root)).max())
               for link, pose in ours.items())


@pytest.mark.parametrize('name', MODELS)
def test_forward_kinematics_equals_yourdfpy(name: str) -> None:
    text = model_text(name)
    robot = parse_urdf(text, name)
    ref = reference(text)
    rng = random.Random(name)
    for _ in range(20):
        positions = random_positions(robot, rng)
        assert largest_difference(robot, ref, positions) < 1e-9, positions
    if name.startswith(('06', '07', '08')):  # the movable ones: R2D2's 8 joints
        assert len(joint_table(robot).free) == 8


MIMIC = """<?xml version="1.0"?>
<robot name="gripper">
  <link name="base"/>
  <link name="finger_a"/>
  <link name="finger_b"/>
  <link name="slider"/>
  <joint name="a" type="revolute">
    <parent link="base"/><child link="finger_a"/>
    <origin xyz="0.1 0 0.2" rpy="0.3 -0.2 1.0"/><axis xyz="0 1 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="b" type="revolute">
    <parent link="base"/><child link="finger_b"/>
    <origin xyz="-0.1 0 0.2" rpy="0 0 3.14159"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
    <mimic joint="a" multiplier="-1.5" offset="0.25"/>
  </joint>
  <joint name="s" type="prismatic">
    <parent link="finger_b"/><child link="slider"/>
    <axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="1" velocity="1"/>
    <safety_controller soft_lower_limit="0.05" soft_upper_limit="0.1" k_velocity="1"/>
  </joint>
</robot>
"""


def test_mimic_joints_follow_their_leader_as_yourdfpy_computes() -> None:
    robot = parse_urdf(MIMIC)
    table = joint_table(robot)
    assert table.order == ['a', 'b', 's'] and set(table.free) == {'a', 's'}
    # the soft limits narrow the range; a range without 0 starts in its middle
    assert (table.free['s'].lower, table.free['s'].upper) == (0.05, 0.1)
    assert table.free['s'].zero == pytest.approx(0.075)
    table.free['a'].position = 0.4
    assert table.positions()[1] == pytest.approx(0.4 * -1.5 + 0.25)
    ref = reference(MIMIC)
    rng = random.Random(3)
    for _ in range(10):
        positions = {'a': rng.uniform(-1, 1), 's': rng.uniform(0, 0.2)}
        assert largest_difference(robot, ref, positions) < 1e-9


def test_quaternions_are_unit_and_keep_kdls_sign() -> None:
    rng = random.Random(5)
    for _ in range(200):
        r = rpy_matrix(*(rng.uniform(-math.pi, math.pi) for _ in range(3)))
        x, y, z, w = quaternion(r)
        assert abs(x * x + y * y + z * z + w * w - 1.0) < 1e-12
        if r[0][0] + r[1][1] + r[2][2] > 1e-6:
            assert w > 0
    # a half turn about z: KDL's largest-diagonal branch gives +z
    assert quaternion(rpy_matrix(0.0, 0.0, math.pi)) == pytest.approx((0, 0, 1, 0), abs=1e-12)


def lines_of(text: str) -> dict[str, int]:
    return {line.strip(): n for n, line in enumerate(text.splitlines(), 1)}


def test_a_wrong_parent_link_names_the_joints_line_and_the_link_meant() -> None:
    text = (SHARE / 'urdf' / '03-origins.urdf').read_text().replace(
        '<parent link="base_link"/>', '<parent link="base_lnk"/>')
    with pytest.raises(UrdfError) as caught:
        parse_urdf(text, 'origins.urdf')
    line = next(n for n, row in enumerate(text.splitlines(), 1) if '<joint name=' in row)
    assert str(caught.value) == (
        f"origins.urdf:{line}: joint 'base_to_right_leg' names parent link 'base_lnk', "
        "which no <link> defines — fix: did you mean 'base_link'? name an existing link, "
        'or add <link name="base_lnk"/>')


@pytest.mark.parametrize(('change', 'message'), [
    (('<limit effort="1000.0" lower="-0.38" upper="0" velocity="0.5"/>', ''),
     "joint 'gripper_extension' is prismatic but has no <limit> (urdfdom refuses it)"),
    (('<origin xyz="0 0 0.3"/>', '<origin xyz="0 0.3"/>'),
     'joint \'head_swivel\' <origin> xyz="0 0.3" is not three numbers'),
    (('<robot name="visual">', '<robot>'), 'the <robot> has no name'),
    (('<link name="head">', '<link name="box">'), "link 'box' is not unique (also line"),
    (('<child link="right_gripper"/>', '<child link="left_gripper"/>'),
     "link 'left_gripper' is the child of two joints: 'left_gripper_joint'"),
    (('</robot>', '<link name="lost"/></robot>'), "two root links: 'base_link' and 'lost'"),
    (('<joint name="tobox" type="fixed">', '<joint name="tobox" type="fixd">'),
     'joint \'tobox\' has type "fixd", which URDF does not know'),
    (('</robot>', '<oops></robot>'), 'not well-formed XML: mismatched tag'),
])
def test_urdfdoms_refusals_are_one_line_with_a_line_and_a_fix(
        change: tuple[str, str], message: str) -> None:
    text = (SHARE / 'urdf' / '06-flexible.urdf').read_text()
    assert change[0] in text
    with pytest.raises(UrdfError) as caught:
        parse_urdf(text.replace(change[0], change[1], 1), '06.urdf')
    err = caught.value
    assert message in err.message and err.file == '06.urdf' and err.line and err.fix
    assert '\n' not in str(err)


def test_an_error_in_xacros_output_names_the_xacro_file() -> None:
    from robot_lab.urdf.state_publisher import read_description

    source = SHARE / 'urdf' / '08-macroed.urdf.xacro'
    text = model_text(source.name).replace('<parent link="base_link"/>',
                                           '<parent link="bse_link"/>', 1)
    with pytest.raises(UrdfError) as caught:
        read_description(text)
    line = next(n for n, row in enumerate(text.splitlines(), 1) if 'bse_link' in row) - 1
    assert str(caught.value).startswith(f"robot_description:{line}: joint 'base_to_right_leg'")
    assert str(caught.value).endswith(f"(line {line} of `xacro {source}`'s output)")


def test_a_revolute_joint_without_limits_says_which_limit_to_write() -> None:
    text = """<robot name="r"><link name="a"/><link name="b"/>
    <joint name="elbow" type="revolute"><parent link="a"/><child link="b"/></joint></robot>"""
    with pytest.raises(UrdfError) as caught:
        parse_urdf(text, 'arm.urdf')
    assert str(caught.value).startswith(
        "arm.urdf:2: joint 'elbow' is revolute but has no <limit> (urdfdom refuses it) — fix: "
        'add <limit lower="-1.57" upper="1.57" effort="10" velocity="1"/>')


def test_check_urdf_prints_urdfdoms_report(tmp_path: Path) -> None:
    urdf = tmp_path / 'r2d2.urdf'
    urdf.write_text(model_text('08-macroed.urdf.xacro'))
    done = subprocess.run([str(BIN / 'check_urdf'), str(urdf)], capture_output=True,
                          text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        'robot name is: macroed',
        '---------- Successfully Parsed XML ---------------',
        'root Link: base_link has 4 child(ren)',
        '    child(1):  left_leg',
        '        child(1):  left_base',
        '            child(1):  left_back_wheel',
        '            child(2):  left_front_wheel',
        '    child(2):  right_leg',
        '        child(1):  right_base',
        '            child(1):  right_back_wheel',
        '            child(2):  right_front_wheel',
        '    child(3):  gripper_pole',
        '        child(1):  left_gripper',
        '            child(1):  left_tip',
        '        child(2):  right_gripper',
        '            child(1):  right_tip',
        '    child(4):  head',
        '        child(1):  box',
    ]
    broken = tmp_path / 'broken.urdf'
    broken.write_text(urdf.read_text().replace('<parent link="base_link"/>',
                                               '<parent link="bas_link"/>', 1))
    done = subprocess.run([str(BIN / 'check_urdf'), str(broken)], capture_output=True,
                          text=True, check=False)
    assert done.returncode == 255 and done.stdout == ''
    first, last = done.stderr.splitlines()
    assert first.startswith(f'Error:   {broken}:') and "did you mean 'base_link'?" in first
    assert last == 'ERROR: Model Parsing the xml failed'
    xacro = subprocess.run([str(BIN / 'check_urdf'),
                            str(SHARE / 'urdf' / '08-macroed.urdf.xacro')],
                           capture_output=True, text=True, check=False)
    assert xacro.returncode == 255 and 'expand it first: xacro' in xacro.stderr


def test_xacro_finds_kit_packages_without_a_sourced_prefix(tmp_path: Path) -> None:
    """The venv's `xacro` in a terminal that sourced nothing: `$(find urdf_tutorial)` is
    the venv's share folder (PyPI's xacro alone: AMENT_PREFIX_PATH 'not set or empty')."""
    source = tmp_path / 'with_mesh.urdf.xacro'
    source.write_text(
        '<robot name="m" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="$(find urdf_tutorial)/urdf/01-myfirst.urdf"/>\n'
        '  <link name="finger"><visual><geometry>\n'
        '    <mesh filename="file://$(find urdf_tutorial)/meshes/l_finger.dae"/>\n'
        '  </geometry></visual></link>\n'
        '  <joint name="grip" type="fixed"><parent link="base_link"/><child link="finger"/>'
        '</joint>\n</robot>\n')
    env = {k: v for k, v in os.environ.items() if k != 'AMENT_PREFIX_PATH'}
    done = subprocess.run([str(BIN / 'xacro'), str(source)], capture_output=True, text=True,
                          env=env, check=False)
    assert done.returncode == 0, done.stderr
    assert f'file://{SHARE}/meshes/l_finger.dae' in done.stdout
    assert (SHARE / 'meshes' / 'l_finger.dae').is_file()
    assert set(parse_urdf(done.stdout).links) == {'base_link', 'finger'}


def test_dependent_joints_chain_and_a_loop_is_refused() -> None:
    """joint_state_publisher's dependent_joints: a chain multiplies factors and carries
    offsets (b = 2·a + 1, then s = 3·b − 1); a loop is an error, as upstream exits."""
    from robot_lab.urdf.joints import Dependent

    robot = parse_urdf(MIMIC)
    table = joint_table(robot, zeros={'a': 0.5}, use_mimic_tags=False,
                        dependent={'b': Dependent('a', 2.0, 1.0), 's': Dependent('b', 3.0, -1.0)})
    assert table.order == ['a', 'b', 's'] and set(table.free) == {'a'}
    assert table.positions() == pytest.approx([0.5, 2.0, 5.0])
    looped = joint_table(robot, use_mimic_tags=False,
                         dependent={'b': Dependent('s'), 's': Dependent('b')})
    with pytest.raises(ValueError, match='infinite recursive mimic chain'):
        looped.positions()


@pytest.mark.parametrize(('parent', 'hint'), [
    ('base', "did you mean 'base_link'? "),  # a shortened name
    ('bsae_link', "did you mean 'base_link'? "),  # a typo
    ('wheel', ''),  # nothing like it; never the joint's own child
])
def test_a_missing_links_hint_names_only_a_link_that_was_likely_meant(
        parent: str, hint: str) -> None:
    text = (f'<robot name="r"><link name="base_link"/><link name="wheel_link"/>'
            f'<joint name="j" type="continuous"><parent link="{parent}"/>'
            '<child link="wheel_link"/></joint></robot>')
    with pytest.raises(UrdfError) as caught:
        parse_urdf(text, 'r.urdf')
    assert caught.value.fix == f'{hint}name an existing link, or add <link name="{parent}"/>'
