"""The package grader on a Chapter 7 description package (issue 49, Deliver 5): the rubric
`ch7-description`'s optional lines `urdf_describes` (check_urdf clean, the expected links,
root, parents and joint types) and `tf_tree` (a tf2 listener's view of the running graph).

The fixture, tests/data/description_robot/my_robot_description, is notebook 12's package
with a launch file of its own: the Chapter 6 robot in xacro (a wheel macro included with
`$(find my_robot_description)`), robot_state_publisher and joint_state_publisher. Its
mistakes are graded from the files and from the TF edges a run would hear (no ROS); one
real job grades the package itself, with full marks.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import REPO

from robot_lab.grading.package.tf_watch import TfEdge

FIXTURE = REPO / 'tests' / 'data' / 'description_robot' / 'my_robot_description'
MODEL = 'urdf/my_robot.urdf.xacro'
TEMP_SENSOR = FIXTURE.joinpath(MODEL).read_text().split('\n\n')[-1].rsplit('</robot>')[0]
EDGES = {('base_link', 'left_wheel', False), ('base_link', 'right_wheel', False),
         ('base_link', 'caster', True), ('base_link', 'temp_sensor_link', True)}


def _package(tmp_path: Path, old: str = '', new: str = '', file: str = MODEL) -> Path:
    """The fixture copied into a workspace's src/, with `old` replaced by `new` in `file`."""
    package = tmp_path / 'ws' / 'src' / 'my_robot_description'
    shutil.copytree(FIXTURE, package)
    if old:
        text = (package / file).read_text()
        assert old in text, f'{old!r} not in {file}'
        (package / file).write_text(text.replace(old, new))
    return package


def _state(package: Path) -> Any:
    from robot_lab.grading.package.rubric import load_rubric, rubric_path
    from robot_lab.grading.package.state import JobState

    return JobState(load_rubric(rubric_path('ch7-description')), package=package,
                    package_name=package.name)


def _verdict(state: Any, check_id: str) -> Any:
    from robot_lab.grading.package.registry import registered_checks

    entry = registered_checks()[check_id]
    assert entry.stage == {'urdf_describes': 'files', 'tf_tree': 'run'}[check_id]
    return entry.run(state, state.rubric.check(check_id))


def test_the_rubric_ships_the_description_lines() -> None:
    from robot_lab.grading.package.rubric import load_rubric, rubric_path

    rubric = load_rubric(rubric_path('ch7-description'))
    assert rubric.ids == ['builds', 'launch_file', 'urdf_describes', 'tf_tree', 'readme']
    assert rubric.check('tf_tree').option('root', '') == 'base_link'  # type: ignore[union-attr]


@pytest.mark.no_ros
@pytest.mark.parametrize(('file', 'old', 'new', 'earned', 'says'), [
    # correct: the xacro's $(find my_robot_description) resolves to the job's workspace
    (MODEL, '', '', True, r'^`urdf/my_robot\.urdf\.xacro`: robot `my_robot`, root `base_link`, '
                          r'5 links, 4 joints$'),
    # a wrong parent link: the caster on a wheel
    (MODEL, '<parent link="base_link"/>\n    <child link="caster"/>',
     '<parent link="left_wheel"/>\n    <child link="caster"/>', False,
     r'; but `caster` has parent `left_wheel` \(joint `caster_joint`, '
     r'urdf/my_robot\.urdf\.xacro:15\), not `base_link`$'),
    # a revolute joint without limits, in the included macro: xacro's output is checked,
    # and the joint's name is made by the macro (`${side}_wheel_joint`)
    ('urdf/wheel.xacro', 'type="continuous"', 'type="revolute"', False,
     r"^check_urdf refuses it: urdf/my_robot\.urdf\.xacro: line \d+ of xacro's output: "
     r"joint 'left_wheel_joint' is revolute but has no <limit>"),
    # ... and in the model itself: its own line
    (MODEL, '<joint name="caster_joint" type="fixed">',
     '<joint name="caster_joint" type="revolute">', False,
     r"^check_urdf refuses it: urdf/my_robot\.urdf\.xacro:15: joint 'caster_joint' is "
     r'revolute but has no <limit>'),
    # a missing link, with its joint
    (MODEL, TEMP_SENSOR, '', False,
     r'; but no link `temp_sensor_link`; no joint `temp_sensor_joint`$'),
    # a renamed link: its joint names a link that is not there
    (MODEL, '<link name="temp_sensor_link">', '<link name="temperature_sensor">', False,
     r"urdf/my_robot\.urdf\.xacro:24: joint 'temp_sensor_joint' names child link "
     r"'temp_sensor_link', which no <link> defines"),
    # an include xacro cannot find: xacro's own message
    (MODEL, '$(find my_robot_description)', '$(find my_robot_descriptoin)', False,
     r'^check_urdf refuses it: .*my_robot_descriptoin'),
])
def test_a_description_is_graded_from_its_files(tmp_path: Path, file: str, old: str,
                                                new: str, earned: bool,
                                                says: str | None) -> None:
    state = _state(_package(tmp_path, old, new, file))
    verdict = _verdict(state, 'urdf_describes')
    assert verdict.earned is earned, verdict.observed
    if says is not None:
        assert re.search(says, verdict.observed), verdict.observed
    if not earned:
        assert verdict.fix, verdict


@pytest.mark.no_ros
def test_the_model_is_found_in_urdf_before_a_macro_file(tmp_path: Path) -> None:
    from robot_lab.grading.package.checks.description import description_files

    package = _package(tmp_path)
    (package / 'test').mkdir()
    (package / 'test' / 'old.urdf').write_text('<robot name="old"/>')
    found = [str(p.relative_to(package)) for p in description_files(package)]
    assert found == [MODEL, 'urdf/wheel.xacro', 'test/old.urdf']


@pytest.mark.no_ros
def test_a_grader_that_cannot_run_xacro_keeps_the_points(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    import subprocess

    from robot_lab.grading.package import job

    def no_xacro(*args: Any, **kwargs: Any) -> None:
        raise FileNotFoundError(2, 'No such file or directory', 'xacro')

    state = _state(_package(tmp_path))
    monkeypatch.setattr(subprocess, 'run', no_xacro)
    job.score_stage(state, 'files')
    outcome = state.outcomes['urdf_describes']
    assert (outcome.score, outcome.max_score) == (2, 2), outcome.output
    assert outcome.grader_error == "FileNotFoundError: [Errno 2] No such file or directory: 'xacro'"
    assert 'Grader error' in outcome.output and 'How to fix' not in outcome.output


def _run_state(tmp_path: Path, edges: set[tuple[str, str, bool]]) -> Any:
    """The run stage as the watch and the tf2 listener leave it, with these TF edges."""
    from robot_lab.grading.package.roles import Observation, Roles, TopicSeen

    state = _state(_package(tmp_path))
    obs = Observation()
    obs.topics['/robot_description'] = TopicSeen('/robot_description', ['std_msgs/msg/String'],
                                                 publishers=['/robot_state_publisher'])
    state.live.obs, state.live.roles = obs, Roles()
    state.live.tf_edges = {TfEdge(*edge) for edge in edges}
    return state


@pytest.mark.no_ros
@pytest.mark.parametrize(('edges', 'says'), [
    (EDGES, None),
    (EDGES - {('base_link', 'right_wheel', False)},
     r'no transform base_link → right_wheel \(joint `right_wheel_joint`\) \(a moving joint '
     r'is published only when /joint_states gives its position'),
    (EDGES | {('left_wheel', 'caster', True)},
     r'`caster` has the parent\(s\) base_link, left_wheel in the TF tree, not `base_link`'),
    (EDGES | {('odom', 'base_link', False)}, r"the TF tree's root is `odom`, not `base_link`$"),
])
def test_the_tf_tree_heard_is_compared_with_the_model(tmp_path: Path,
                                                      edges: set[tuple[str, str, bool]],
                                                      says: str | None) -> None:
    verdict = _verdict(_run_state(tmp_path, edges), 'tf_tree')
    assert verdict.earned is (says is None), verdict.observed
    if says is not None:
        assert re.search(says, verdict.observed), verdict.observed


@pytest.mark.timeout(300)
def test_a_class_run_grades_the_description_package(tmp_path: Path) -> None:
    """A real job: colcon build, the student's launch file, a tf2 listener on the graph."""
    from robot_lab.grading.package.grade import grade_class, resolve_rubric

    shutil.copytree(FIXTURE, tmp_path / 'class' / 'ada')
    run = grade_class(tmp_path / 'class', resolve_rubric('ch7-description', None),
                      tmp_path / 'out', jobs=1, progress=False)
    report = run.reports[0]
    checks = {c.id: c for c in report.checks}
    assert report.status == 'graded', report.markdown()
    assert {i: c.score for i, c in checks.items()} == {
        'builds': 1, 'launch_file': 1, 'urdf_describes': 2, 'tf_tree': 2, 'readme': 1}, \
        report.markdown()
    # the four joints, the fixed ones from the one transient-local /tf_static message
    assert 'the TF tree heard: 4 edges' in checks['tf_tree'].output, report.markdown()


@pytest.mark.no_ros
def test_one_job_expands_the_xacro_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """urdf_describes (files) and tf_tree (run) read the same model: one xacro run."""
    import subprocess

    real = subprocess.run
    programs: list[str] = []

    def counted(args: Any, *rest: Any, **kwargs: Any) -> Any:
        programs.append(Path(args[0]).name)
        return real(args, *rest, **kwargs)

    state = _run_state(tmp_path, EDGES)
    monkeypatch.setattr(subprocess, 'run', counted)
    assert _verdict(state, 'urdf_describes').earned
    assert _verdict(state, 'tf_tree').earned
    assert programs.count('xacro') == 1, programs
