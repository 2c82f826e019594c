"""The package grader's `sim_behaviour` check (issue 50, Deliver 7): the student's controller
drives a robot in the kit's simulator, graded by the simulator's ground truth.

The fixture, tests/data/sim_controller/wall_stopper, is the Module 2 exercise handed in:
a controller against /scan with a launch file that sets use_sim_time. One class run grades
it and a copy that never stops, on a wall, in two parallel jobs; the rubric's options are
validated on load, each error at the option's own line.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from conftest import REPO

from robot_lab.sim.sample_robot import diffbot_urdf

FIXTURE = REPO / 'tests' / 'data' / 'sim_controller' / 'wall_stopper'


@pytest.mark.no_ros
@pytest.mark.parametrize(('old', 'new', 'says'), [
    ('tolerance: 0.05', 'tolerance: -1',
     r':LINE: check sim_behaviour: tolerance must be a number > 0 \(got -1\) — fix: write e\.g\. '
     r'`tolerance: 0\.05`$'),
    ('behaviour: stop_before_obstacle', 'behaviour: follow_wall',
     r":LINE: check sim_behaviour: behaviour 'follow_wall' is not one the kit grades — fix: "
     r'write `behaviour: stop_before_obstacle`$'),
    ('target: 0.3', 'targte: 0.3', r':LINE: check sim_behaviour: unknown option\(s\) targte'),
    ('obstacle_distance: 1.0', 'obstacle_distance: 0.2',
     r':LINE: check sim_behaviour: obstacle_distance must be more than target'),
])
def test_a_wrong_option_is_named_at_its_line(tmp_path: Path, old: str, new: str,
                                             says: str) -> None:
    from robot_lab.errors import RobotLabError
    from robot_lab.grading.package.rubric import load_rubric, rubric_path

    text = rubric_path('ch8-sim').read_text()
    assert old in text
    says = says.replace('LINE', str(text[:text.index(old)].count('\n') + 1))
    wrong = tmp_path / 'rubric.yaml'
    wrong.write_text(text.replace(old, new))
    with pytest.raises(RobotLabError) as caught:
        load_rubric(wrong)
    assert str(caught.value).startswith(str(wrong))
    assert re.search(says, str(caught.value)), str(caught.value)


@pytest.mark.timeout(300)
def test_a_class_run_grades_the_behaviour_in_the_simulator(tmp_path: Path) -> None:
    """Real jobs: colcon build, the student's launch file, the simulator, the referee."""
    from robot_lab.grading.package.grade import grade_class, resolve_rubric
    from robot_lab.grading.package.rubric import rubric_path

    shutil.copytree(FIXTURE, tmp_path / 'class' / 'ada')
    bob = tmp_path / 'class' / 'bob'
    shutil.copytree(FIXTURE, bob)
    launch = bob / 'launch' / 'stopper.launch.py'  # never stops, on the wall clock
    launch.write_text(launch.read_text().replace(
        "{'use_sim_time': True, 'stop_distance': 0.3}", "{'stop_distance': -5.0}"))
    # The run stage's watch waits its whole startup for a /scan no one publishes there:
    # a shorter one (the launch is a single node) keeps the test short.
    rubric = tmp_path / 'ch8-sim.yaml'
    rubric.write_text(rubric_path('ch8-sim').read_text().replace('startup_seconds: 12',
                                                                 'startup_seconds: 6'))
    run = grade_class(tmp_path / 'class', resolve_rubric(None, str(rubric)), tmp_path / 'out',
                      jobs=2, progress=False)
    reports = {r.student: r for r in run.reports}
    ada = {c.id: c for c in reports['ada'].checks}
    assert reports['ada'].status == 'graded', reports['ada'].markdown()
    assert {i: c.score for i, c in ada.items()} == {
        'builds': 1, 'launch_file': 1, 'sim_behaviour': 4, 'readme': 1}, \
        reports['ada'].markdown()
    assert re.search(r'stopped 0\.(2[5-9]|3[0-5]) m from the wall at t=\d+\.\d s '
                     r'\(sim time\) \(target 0\.30 ± 0\.05\)', ada['sim_behaviour'].output), \
        ada['sim_behaviour'].output
    bob_checks = {c.id: c for c in reports['bob'].checks}
    sim = bob_checks['sim_behaviour']
    assert reports['bob'].status == 'graded', reports['bob'].markdown()
    assert sim.score == 0, sim.output
    assert re.search(r'hit the wall at 0\.[23]\d m/s at t=\d+\.\d s \(sim time\); '
                     r'/stopper runs without use_sim_time', sim.output), sim.output
    assert 'slow down as the obstacle nears' in sim.output


_NO_TAGS = """<?xml version="1.0"?>
<robot name="brick">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="1.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""
_BROKEN = diffbot_urdf().replace(  # the sample robot, a joint to a link it has not
    '</robot>', '<joint name="j" type="fixed"><parent link="base_link"/><child link="nowhere"/>'
                '</joint>\n</robot>')


@pytest.mark.parametrize(('option', 'urdf', 'grader_error', 'says'), [
    # the rubric names a world the kit has not: the grader's fault (not the robot's, though
    # the package has one), the points kept
    ({'world': 'no_such_world.sdf'}, diffbot_urdf(), r'^the simulator: .*no_such_world\.sdf',
     r'^not run$'),
    # the student's own robot is refused by the simulator: theirs
    ({}, _BROKEN, '', r'^your robot \(urdf/robot\.urdf\) could not be spawned: .*nowhere'),
    ({}, _NO_TAGS, '', r'^your robot \(urdf/robot\.urdf\) has no lidar \(a gpu_lidar sensor\) '
                       r'and no DiffDrive system$'),
])
def test_what_keeps_the_simulation_from_running_is_blamed_on_whose_fault_it_is(
        tmp_path: Path, option: dict[str, str], urdf: str, grader_error: str,
        says: str) -> None:
    from robot_lab.grading.package.registry import registered_checks
    from robot_lab.grading.package.rubric import RubricCheck, load_rubric, rubric_path
    from robot_lab.grading.package.state import JobState

    package = tmp_path / 'wall_stopper'
    shutil.copytree(FIXTURE, package)
    if urdf:
        (package / 'urdf').mkdir()
        (package / 'urdf' / 'robot.urdf').write_text(urdf)
    rubric = load_rubric(rubric_path('ch8-sim'))
    shipped = rubric.check('sim_behaviour')
    assert shipped is not None
    check = RubricCheck(shipped.id, shipped.name, shipped.points, {**shipped.options, **option})
    state = JobState(rubric, package=package, package_name=package.name, built=True)
    verdict = registered_checks()['sim_behaviour'].run(state, check)
    assert re.search(grader_error, verdict.grader_error) if grader_error else \
        not verdict.grader_error, verdict
    assert verdict.earned is False
    assert re.search(says, verdict.observed), verdict.observed
