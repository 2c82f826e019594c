"""The grader's own failures are never a student's loss (issue 51): a failure in a grader
call (a graph query, a parameter read, the perturbation, a file read, a stage) gives the
check its points, marked as a grader error; the summary and the run's last line name the
students to regrade with --only; parameter reads are retried within the job's budget.

One real class run grades the lamp (a Bool command with hysteresis: full marks) beside
three copies of it whose jobs have grader calls made to fail, each through the job's
`argv` (robot_lab.grading.package.sandbox.run_job): every score must equal the lamp's."""

from __future__ import annotations

import functools
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import REPO

from robot_lab.errors import GraphError
from robot_lab.grading.package import job, live
from robot_lab.grading.package.checks.params_used import params_used
from robot_lab.grading.package.registry import RegisteredCheck
from robot_lab.grading.package.rubric import Rubric, RubricCheck
from robot_lab.grading.package.state import JobState, ParamReading, Verdict
from robot_lab.grading.report import CheckOutcome, StudentReport, run_summary

LAMP = REPO / 'tests' / 'data' / 'commands' / 'lamp'


def _state(*checks: RubricCheck) -> JobState:
    return JobState(Rubric('lab', '', list(checks)))


def _registered(monkeypatch: pytest.MonkeyPatch, **verdicts: Any) -> None:
    """Checks named by id, scored after 'run', each returning (or raising) the value."""
    def run(value: Any, state: JobState, check: RubricCheck) -> Verdict:
        if isinstance(value, Exception):
            raise value
        assert isinstance(value, Verdict)
        return value

    table = {cid: RegisteredCheck(cid, 'run', functools.partial(run, value))
             for cid, value in verdicts.items()}
    monkeypatch.setattr(job, 'registered_checks', lambda: table)


def test_a_grader_error_keeps_the_points_and_a_real_loss_stays(
        monkeypatch: pytest.MonkeyPatch) -> None:
    checks = [RubricCheck(cid, cid, 2.0) for cid in ('raised', 'told', 'lost', 'passed')]
    _registered(monkeypatch, raised=OSError(5, 'Input/output error'),
                told=Verdict(False, 'e', 'o', grader_error='param read timed out'),
                lost=Verdict(False, 'e', 'o', 'fix it'), passed=Verdict(True, 'e', 'o'))
    state = _state(*checks)
    job.score_stage(state, 'run')
    scores = {cid: (o.score, bool(o.grader_error)) for cid, o in state.outcomes.items()}
    assert scores == {'raised': (2.0, True), 'told': (2.0, True), 'lost': (0.0, False),
                      'passed': (2.0, False)}
    assert 'Grader error' in state.outcomes['told'].output
    assert len(state.grader_errors) == 2


def test_a_stage_that_raised_keeps_the_points_of_the_checks_it_starved(
        monkeypatch: pytest.MonkeyPatch) -> None:
    _registered(monkeypatch, starved=Verdict(False, 'e', 'nothing ran'),
                passed=Verdict(True, 'e', 'o'))
    state = _state(RubricCheck('starved', 's', 2.0), RubricCheck('passed', 'p', 1.0))
    state.stage_faults['build'] = 'OSError: [Errno 28] No space left on device (build.py:9)'
    job.score_stage(state, 'run')
    assert state.outcomes['starved'].score == 2.0
    assert 'No space left' in state.outcomes['starved'].grader_error
    assert not state.outcomes['passed'].grader_error


def test_a_fault_named_for_a_check_keeps_its_points_only_there(
        monkeypatch: pytest.MonkeyPatch) -> None:
    _registered(monkeypatch, watched=Verdict(False, 'e', 'no sensor'),
                other=Verdict(False, 'e', 'wrong value'))
    state = _state(RubricCheck('watched', 'w', 2.0), RubricCheck('other', 'o', 1.0))
    state.check_faults['watched'] = "/lamp's topics could not be read: RuntimeError"
    job.score_stage(state, 'run')
    assert (state.outcomes['watched'].score, state.outcomes['other'].score) == (2.0, 0.0)


def _params_state(*readings: ParamReading) -> JobState:
    state = _state(RubricCheck('params_used', 'p', 1.0))
    state.live.params_loaded = {'/ws/config/lamp.yaml': ['lamp_controller']}
    state.live.alive_nodes = {'/lamp_controller'}
    state.live.readings = list(readings)
    return state


def test_a_parameter_the_grader_could_not_read_is_not_a_wrong_one() -> None:
    timeout = 'GraphError: /lamp_controller/get_parameters: no answer within 5 s'
    unread = ParamReading('lamp_controller', 'on_below_lux', 200.0, '/lamp_controller',
                          error=timeout)
    read = ParamReading('lamp_controller', 'off_above_lux', 250.0, '/lamp_controller', 250.0)
    verdict = params_used(_params_state(unread, read), RubricCheck('params_used', 'p', 1.0))
    assert verdict.grader_error.startswith('1 parameter read(s) failed'), verdict
    assert 'could not read it' in verdict.observed
    wrong = ParamReading('lamp_controller', 'off_above_lux', 250.0, '/lamp_controller', 9.0)
    verdict = params_used(_params_state(unread, wrong), RubricCheck('params_used', 'p', 1.0))
    assert not verdict.grader_error and verdict.fraction == 0  # a wrong value is a real loss


def test_a_parameter_read_is_retried_within_the_budget(monkeypatch: pytest.MonkeyPatch) -> None:
    import time

    import robot_lab.graph.parameters as parameters

    calls: list[str] = []

    def flaky(node: str, name: str, session: Any = None, unset_ok: bool = False
              ) -> tuple[int, Any]:
        calls.append(name)
        if name == 'never' or len(calls) < 3:
            raise GraphError(f'{node}/get_parameters: no answer within 5 s')
        return 3, 200.0

    monkeypatch.setattr(parameters, 'param_get_typed', flaky)
    soon = time.monotonic() + 30
    assert live._read_param(None, '/lamp', 'on_below', soon) == (True, 200.0, '')  # type: ignore[arg-type]
    assert len(calls) == 3
    answered, _, error = live._read_param(None, '/lamp', 'never', soon)  # type: ignore[arg-type]
    assert not answered and 'no answer within 5 s' in error and len(calls) == 6
    answered, _, error = live._read_param(None, '/lamp', 'x', time.monotonic())  # type: ignore[arg-type]
    assert not answered and 'run out' in error and len(calls) == 6  # no budget: no call


def test_a_node_that_left_the_graph_is_not_asked_again(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from types import SimpleNamespace

    import robot_lab.graph.discovery as discovery
    import robot_lab.graph.parameters as parameters

    asked: list[tuple[str, str]] = []

    def dead(node: str, name: str, session: Any = None, unset_ok: bool = False
             ) -> tuple[int, Any]:
        asked.append((node, name))
        raise GraphError(f'{node}/get_parameters: no answer within 5 s')

    monkeypatch.setattr(parameters, 'param_get_typed', dead)
    monkeypatch.setattr(discovery, 'full_node_names', lambda sess, include_hidden: ['/other'])
    file = tmp_path / 'lamp.yaml'
    file.write_text('lamp:\n  ros__parameters:\n    on_below: 200.0\n    off_above: 250.0\n')
    state = _state(RubricCheck('params_used', 'p', 1.0))
    state.param_files = [file]
    spec = SimpleNamespace(param_files=[str(file)], node_name='lamp', executable='lamp')
    plan = SimpleNamespace(processes=lambda: [spec])
    live._read_params_back(state, plan, None, ['/lamp'])  # type: ignore[arg-type]
    assert asked == [('/lamp', 'on_below')]  # gone after the first read: no retry, no second
    assert [(r.node, r.error) for r in state.live.readings] == [
        ('/lamp', '/lamp has left the graph')] * 2


def test_the_last_line_counts_grader_errors_and_names_the_regrade() -> None:
    ok = StudentReport('ana', [CheckOutcome('builds', 'b', 2, 2)])
    hit = StudentReport('ben', [CheckOutcome('builds', 'b', 2, 2),
                                CheckOutcome('params_used', 'p', 1, 1, grader_error='timeout'),
                                CheckOutcome('readme', 'r', 1, 1, grader_error='OSError')],
                        status='grader error', error='params_used: timeout')
    line = run_summary([ok, hit])
    assert line == ('2 student(s): 1 fully graded, 1 not fully graded: ben (grader error); '
                    '2 grader error(s) in 1 student(s), points kept: regrade with --only ben')


# --- One real run: the lamp and three lamps whose grader calls fail ----------------------

INJECT = """
import json, sys
from pathlib import Path
from robot_lab.errors import GraphError
from robot_lab.grading.package import job, live

job_dir = Path(sys.argv[1])
student = json.loads((job_dir / 'job.json').read_text())['student']

def failing(what):
    def fail(*args, **kwargs):
        raise GraphError(f'{what}: no answer within 5 s (injected)')
    return fail

def broken_disk(*args, **kwargs):
    raise OSError(5, 'Input/output error (injected)')

if student == 'lamp_calls':  # a parameter read, the perturbation, a file read
    import robot_lab.graph.parameters as parameters
    parameters.param_get_typed = failing('/lamp_controller/get_parameters')
    live.drive_controller = failing('perturbation')
    read_text = Path.read_text
    Path.read_text = lambda self, *a, **k: (broken_disk() if self.name == 'README.md'
                                            else read_text(self, *a, **k))
elif student == 'lamp_watch':  # the watch as a whole
    live.observe = failing('get_topic_names_and_types')
elif student == 'lamp_graph':  # the watch's query of each node's topics
    from rclpy.node import Node
    Node.get_publisher_names_and_types_by_node = failing('publishers by node')
elif student == 'lamp_build':  # the build and the parameter file's read
    import robot_lab.params
    job._build = broken_disk
    robot_lab.params.load_param_file = broken_disk
sys.exit(job.main(sys.argv[1:]))
"""
FAILED = {
    'lamp': set(),
    'lamp_calls': {'controller_commands', 'params_used', 'readme'},
    'lamp_watch': {'launch_file', 'sensor_publishes', 'controller_commands', 'actuator_logs',
                   'params_used'},
    'lamp_build': {'builds', 'params_file', 'sensor_publishes', 'controller_commands',
                   'actuator_logs', 'params_used'},
    'lamp_graph': {'sensor_publishes', 'controller_commands', 'actuator_logs'},
}


@pytest.mark.timeout(600)
def test_no_score_drops_when_grader_calls_fail(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    from robot_lab.grading.package import grade, sandbox
    from robot_lab.grading.package.grade import grade_class, resolve_rubric

    for student in FAILED:
        shutil.copytree(LAMP, tmp_path / 'class' / student)
    monkeypatch.setattr(grade, 'run_job', functools.partial(sandbox.run_job,
                                                            argv=('-c', INJECT)))
    out = tmp_path / 'out'
    run = grade_class(tmp_path / 'class', resolve_rubric('ch6-lab1', None), out, jobs=3,
                      progress=False)
    reports = {r.student: r for r in run.reports}
    lamp = reports['lamp']
    feedback = {c.id: c.output for c in lamp.checks}
    assert (lamp.score, lamp.status) == (13, 'graded'), lamp.markdown()
    assert 'fields that changed with the input: `data`' in feedback['controller_commands']
    for student, failed in FAILED.items():
        report = reports[student]
        assert report.score == lamp.score, report.markdown()
        assert {c.id for c in report.checks if c.grader_error} == failed, report.markdown()
        assert report.status == ('grader error' if failed else 'graded')
        for check in report.checks:  # nothing for the student to fix there
            assert not check.grader_error or 'How to fix' not in check.output, check.output
        assert report.markdown().count('(grader error, points kept)') == len(failed)
    line = run_summary(run.reports)
    assert line.endswith('; 17 grader error(s) in 4 student(s), points kept: regrade with '
                         '--only lamp_build,lamp_calls,lamp_graph,lamp_watch'), line
    summary = (out / 'summary.html').read_text()
    assert 'Grader errors (points kept) (4)' in summary
    assert '--only lamp_build,lamp_calls,lamp_graph,lamp_watch' in summary
