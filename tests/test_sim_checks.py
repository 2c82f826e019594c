"""Lesson 13's checks (robot_lab.grading.check.sim) on files and on a trial's figures, with
no simulator: the `<gazebo>` tags' mistakes each get their own message, and the stop
check's advice follows what the trial found first (wiring, collision, clock, distance).

The notebook's own ladders (tests/test_mistake_path_simulation.py) walk the same messages
in a real kernel, with the simulator and the bridge running.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from robot_lab.grading import CheckError, check
from robot_lab.grading.check.sim import _stop_hint
from robot_lab.sim.sample_robot import WHEEL_RADIUS, WHEEL_SEPARATION, diffbot_urdf
from robot_lab.sim.trial_result import TrialResult

pytestmark = pytest.mark.no_ros


def _model(tmp_path: Path, *swaps: str) -> Path:
    text = diffbot_urdf(name='my_robot')
    for old, new in zip(swaps[::2], swaps[1::2], strict=True):
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / 'my_robot.urdf'
    path.write_text(text)
    return path


def test_the_sample_robots_tags_pass(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    check.gazebo_tags(_model(tmp_path))
    said = capsys.readouterr().out
    assert said.startswith('✓ my_robot.urdf: DiffDrive turns left_wheel_joint and '
                           'right_wheel_joint'), said
    assert f'({WHEEL_SEPARATION:g} m apart, radius {WHEEL_RADIUS:g} m)' in said
    assert 'a lidar on laser_frame publishes scan (360 beams, 10 Hz)' in said


WRONG = {
    'no DiffDrive': (('name="gz::sim::systems::DiffDrive"', 'name="gz::sim::systems::Other"'),
                     r'observed no <plugin name="gz::sim::systems::DiffDrive">'),
    'links, not joints': (('<left_joint>left_wheel_joint<', '<left_joint>left_wheel<'),
                          r"left_joint is 'left_wheel', a link, not a joint"),
    'sides swapped': (('<left_joint>left_wheel_joint<', '<left_joint>right_wheel_joint<',
                       '<right_joint>right_wheel_joint<', '<right_joint>left_wheel_joint<'),
                      r'right of the robot.*Try: swap <left_joint> and <right_joint>'),
    'separation': ((f'<wheel_separation>{WHEEL_SEPARATION}<', '<wheel_separation>0.5<'),
                   r'<wheel_separation> 0\.5 m \(the wheel joints are 0\.35 m apart\)'),
    'radius': ((f'<wheel_radius>{WHEEL_RADIUS}<', '<wheel_radius>0.1<'),
               r'<wheel_radius> 0\.1 m \(the wheel cylinders have radius 0\.05\)'),
    'command topic': (('<topic>cmd_vel</topic>', '<topic>/model/my_robot/cmd_vel</topic>'),
                      r"DiffDrive's <topic> is /model/my_robot/cmd_vel.*<topic>cmd_vel"),
    'lidar topic': (('<topic>scan</topic>', '<topic>lidar</topic>'),
                    r'the lidar publishes gz topic lidar.*Try: write <topic>scan</topic>'),
    'lidar link': (('<gazebo reference="laser_frame">', '<gazebo reference="lidar_link">'),
                   r"the lidar is on link 'lidar_link', which the robot does not have"),
}


@pytest.mark.parametrize('mistake', list(WRONG))
def test_each_tag_mistake_says_what_to_write(tmp_path: Path, mistake: str) -> None:
    swaps, says = WRONG[mistake]
    with pytest.raises(CheckError) as failure:
        check.gazebo_tags(_model(tmp_path, *swaps))
    assert str(failure.value).startswith('✗ expected my_robot.urdf to tell the simulator')
    assert re.search(says, str(failure.value), re.S), str(failure.value)


def _result(**figures: Any) -> TrialResult:
    sample = {'t': 0.0, 'gap': 0.3, 'contact': False, 'x': 0.0, 'y': 0.0, 'yaw': 0.0,
              'commands': 5}
    later = {**sample, 't': 1.0}
    wired: dict[str, Any] = {'scan_publishers': ('/ros_gz_bridge',),
                                'cmd_vel_publishers': ('/stop_at_wall',)}
    return TrialResult.from_samples([sample, later], **{**wired, **figures})


def test_the_stop_checks_advice_follows_the_first_thing_wrong() -> None:
    assert 'bridge /scan' in _stop_hint(_result(scan_publishers=()), 0.3)
    assert "use_sim_time': True" in _stop_hint(
        _result(use_sim_time={'/stop_at_wall': False}), 0.3)
    assert 'target_distance of 0.50 m leaves 0.30 m' in _stop_hint(_result(), 0.3)
