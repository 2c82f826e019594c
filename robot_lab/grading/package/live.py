"""The running part of a package job: launch the student's system and watch it.

Called by robot_lab.grading.package.job after the build, inside the job's sandbox; what
it sees goes into the job's `LiveRun` for the run checks (robot_lab.grading.package.checks).
The student's launch file runs under the kit's launcher; a parameter file that rcl would
refuse is left out (so the behaviour can still be graded; `params_file` reports it) and a
package without a launch file gets every executable started (so only `launch_file` and
`params_used` are lost). The observer is this process's session in the job's domain.

The grader's own calls here (the graph queries of the watch, parameter reads, the
perturbation) can fail on a loaded host: each failure is kept as a grader fault for the
checks it concerns (robot_lab.grading.package.state), never read as the student's
("no node holds it"). A parameter read is retried while the job's budget allows.
"""

from __future__ import annotations

import contextlib
import copy
import os
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import ParamFileError, RobotLabError
from robot_lab.grading.package.perturb import Response, drive_controller
from robot_lab.grading.package.roles import infer_roles, observe
from robot_lab.grading.package.state import JobState, ParamReading, code

if TYPE_CHECKING:
    from robot_lab.grading.package.tf_watch import TfWatch
    from robot_lab.launch.api import LaunchHandle, ProcessStatus
    from robot_lab.launch.plan import LaunchPlan
    from robot_lab.rclpy_session import Session

__all__ = ['run_system']


def _plan_for(state: JobState, job_dir: Path) -> tuple[LaunchPlan | None, str, list[str]]:
    """(plan, feedback on the launch file, notes); the plan may be a stand-in."""
    from robot_lab.launch.api import describe_launch

    notes: list[str] = []
    errors: list[str] = []
    best: tuple[int, LaunchPlan, Path] | None = None
    for path in state.launch_files:
        try:
            plan = describe_launch(state.package_name, path.name)
        except RobotLabError as err:
            try:  # not installed: the source file still tells what it starts
                plan = describe_launch(path)
                notes.append(f'`{path.name}` is not installed (add launch/ to data_files '
                             'in setup.py); it was run from the source folder')
            except RobotLabError:
                errors.append(f'{path.name}: {err}')
                continue
        nodes = len(plan.processes())
        if best is None or nodes > best[0]:
            best = (nodes, plan, path)
    if best is not None:
        return best[1], best[2].name, notes
    if errors:
        notes.extend(errors)
    # No usable launch file: start every executable so the behaviour can be graded.
    from robot_lab.pkg.index import executables

    try:
        names = executables(state.package_name)
    except RobotLabError:
        names = []
    if not names:
        return None, '', notes
    stand_in = job_dir / 'grader_stand_in.launch.xml'
    body = ''.join(f'  <node pkg="{state.package_name}" exec="{name}" output="screen"/>\n'
                   for name in names)
    stand_in.write_text(f'<launch>\n{body}</launch>\n')
    notes.append('the grader started every executable itself (' + ', '.join(names) + ')')
    return describe_launch(stand_in), '', notes


_EMPTY_PARAMS = '/**:\n  ros__parameters: {}\n'


def _neutralise_installed_param_files(state: JobState, ws: Path, package: str) -> list[str]:
    """Installed parameter files rcl would refuse, replaced by an empty valid one.

    The launcher checks every file before starting anything (as rcl would refuse it in
    each node); emptied, the launch starts and the nodes run on their code defaults, so
    the behaviour is still graded while `params_file` and `params_used` report the file.
    """
    share = ws / 'install' / package / 'share' / package
    findings = []
    for path in sorted(share.rglob('*.y*ml')) if share.is_dir() else []:
        if path.name.endswith(('.launch.yaml', '.launch.yml')) or 'launch' in path.parts[-2:-1]:
            continue
        try:
            state.params(path)
        except ParamFileError as err:
            findings.append(f'{path.name}: {err}')
            real = path.resolve()  # a --symlink-install points at the source: keep that
            if real != path:
                path.unlink()
            path.write_text(_EMPTY_PARAMS)
    return findings


def _drop_bad_param_files(state: JobState, plan: LaunchPlan) -> list[str]:
    """Leave out parameter files rcl would refuse (the node would exit at start)."""
    dropped = []
    for spec in plan.processes():
        for path in list(spec.param_files):
            try:
                state.params(path)
            except (ParamFileError, OSError) as err:
                spec.param_files.remove(path)
                i = spec.cmd.index(path) if path in spec.cmd else -1
                if i > 0 and spec.cmd[i - 1] == '--params-file':
                    del spec.cmd[i - 1:i + 1]
                dropped.append(f'{Path(path).name}: {err}')
    return sorted(set(dropped))


def _matches(pattern: str, node: str) -> bool:
    if pattern in ('/**', '**', '/*', '*'):
        return True
    wanted = pattern if pattern.startswith('/') else '/' + pattern
    return wanted == node or (wanted.startswith('/**/') and node.endswith(wanted[3:]))


# Parameter reads: each is tried up to _READ_TRIES times (each try waits up to the parameter
# client's own timeouts), all of them within _READS_BUDGET s and never into the last
# _RESERVE s of the job's budget (the run checks still have to be scored and written).
_READ_TRIES = 3
_READS_BUDGET = 60.0
_RESERVE = 30.0


class _NodeLeftError(Exception):
    """A parameter read found its node gone from the graph (it died): not asked again."""

    def __init__(self, node: str) -> None:
        super().__init__(f'{node} has left the graph')


def _read_param(sess: Session, node: str, name: str, deadline: float) -> tuple[bool, Any, str]:
    """(answered, value or None when the node does not hold it, the grader's error);
    raises _NodeLeftError when a failed read finds the node gone from the graph."""
    from robot_lab.graph.discovery import full_node_names
    from robot_lab.graph.parameters import param_get_typed

    error, pause = 'not tried: the time for parameter reads had run out', 0.25
    for attempt in range(_READ_TRIES):
        if time.monotonic() >= deadline:
            break
        try:
            kind, value = param_get_typed(node, name, session=sess, unset_ok=True)
        except Exception as err:  # a timeout, a lost request: the grader's, not the node's
            error = f'{type(err).__name__}: {err}'
            present = True  # a failed graph query says nothing about the node
            with contextlib.suppress(Exception):
                present = node in full_node_names(sess, include_hidden=False)
            if not present:
                raise _NodeLeftError(node) from err
            if attempt + 1 < _READ_TRIES:
                time.sleep(min(pause, max(0.0, deadline - time.monotonic())))
                pause *= 2
            continue
        return True, (value if kind else None), ''
    return False, None, error


def _read_params_back(state: JobState, plan: LaunchPlan, sess: Session,
                      running: list[str]) -> None:
    """Which of the student's parameter files the launch passes, and the values the running
    nodes hold for each parameter in them (scored by the `params_used` check)."""
    own = {p.name for p in state.param_files}
    live = state.live
    for spec in plan.processes():
        for path in spec.param_files:
            if Path(path).name in own:
                live.params_loaded.setdefault(path, []).append(spec.node_name or spec.executable)
    deadline = time.monotonic() + max(0.0, min(_READS_BUDGET, state.time_left() - _RESERVE))
    gone: set[str] = set()
    for path in live.params_loaded:
        try:
            data = state.params(path)
        except ParamFileError:
            continue
        for pattern, params in data.items():
            nodes = [n for n in running if _matches(pattern, n)]
            for name, value in params.items():
                reading = ParamReading(pattern, name, value, None)
                for node in nodes:
                    if node in gone:
                        reading.node, reading.error = node, str(_NodeLeftError(node))
                        continue
                    try:
                        answered, held, error = _read_param(sess, node, name, deadline)
                    except _NodeLeftError as left:
                        gone.add(node)
                        reading.node, reading.error = node, str(left)
                        continue
                    if not answered:
                        reading.node, reading.error = node, error
                    elif held is not None:
                        reading.node, reading.held, reading.error = node, held, ''
                        break
                live.readings.append(reading)


def _last_logs(output: list[str]) -> str:
    lines = [line for line in output if line.strip()][-8:]
    return code(lines, 8) if lines else ' (no output)'


def run_system(job_dir: Path, ws: Path, state: JobState) -> None:
    """Launch the student's system, observe it, stop it: fills `state.live`."""
    live = state.live
    if not state.built:
        live.not_run = 'not run: the package does not build (see "builds")'
        live.fix = 'fix the build'
        return
    from robot_lab.pkg.workspace import use_workspace

    saved_path = list(sys.path)
    use_workspace(ws, libraries=False)  # for the children: the environment only
    sys.path[:] = saved_path  # the student's modules stay out of the grader
    emptied = _neutralise_installed_param_files(state, ws, state.package_name)
    plan, live.launch_name, live.notes = _plan_for(state, job_dir)
    if plan is None:
        live.not_run = ('no launch file could be run and the package installs no executables'
                        + ''.join(f'\n\n{n}' for n in live.notes))
        live.fix = 'add entry_points console_scripts in setup.py and launch/<name>.launch.xml'
        return
    live.dropped = emptied + _drop_bad_param_files(state, plan)
    _observe(job_dir, state, plan)


# The checks judged from the watch (the graph and the messages it saw).
_WATCHED = ('launch_file', 'sensor_publishes', 'controller_commands', 'actuator_logs')


def _observe(job_dir: Path, state: JobState, plan: LaunchPlan) -> None:
    from robot_lab.grading.package.bridge import Bridge
    from robot_lab.graph.discovery import full_node_names
    from robot_lab.graph.view import graph_view
    from robot_lab.launch.api import LaunchHandle
    from robot_lab.rclpy_session import session

    rubric, live = state.rubric, state.live
    sess = session()
    try:
        launched = time.monotonic()
        handle = LaunchHandle(plan)
    except RobotLabError as err:
        live.not_run = f'the launch did not start: {err}'
        live.fix = err.fix or 'run it yourself with `ros2 launch` and fix the error it prints'
        return
    output: dict[str, list[str]] = {}
    bridge = Bridge()  # for the student's own message types: read by a helper process
    tf = _watch_tf(state, sess)
    # One process may spin several nodes: wait for as many nodes as the lab asks for.
    wanted = max(len(plan.processes()), int(state.option('launch_file', 'min_nodes', 3)))
    try:
        try:
            obs = observe(sess, wanted, rubric.startup_seconds, rubric.observe_seconds,
                          alive=lambda: handle.running,
                          running=lambda: [p.pid for p in handle.processes
                                           if p.state == 'running' and p.pid], bridge=bridge)
        except Exception as err:  # the grader's graph queries, not the student's nodes
            live.grader_fault = f'watching the running system failed: {type(err).__name__}: {err}'
            live.not_run = f'the grader could not watch the running system ({live.grader_fault})'
            return
        live.obs = obs
        if tf is not None:
            live.tf_edges = tf.edges()
        if obs.faults:  # what the watch could not see may have decided these checks
            state.check_faults.update(dict.fromkeys(_WATCHED, '; '.join(obs.faults)))
        with contextlib.suppress(Exception):
            state.images.append(graph_view(session=sess).save(job_dir / 'graph.png'))
        _read_params_back(state, plan, sess, list(obs.nodes))
        live.statuses = handle.processes
        output = {p.label: handle.logs(p.label) for p in live.statuses}
        live.logs = {label: _last_logs(lines) for label, lines in output.items()}
        live.line_rates = {p.name: _line_rate(handle.log_dir / f'{p.label}.log',
                                              time.monotonic() - launched)
                           for p in live.statuses}
        live.alive_nodes = set(full_node_names(sess, include_hidden=False))
        live.roles = infer_roles(obs, float(state.option('sensor_publishes', 'min_rate_hz',
                                                         0.5)))
        # Only controller_commands reads the drive (~15 s: the sensor paused, the topic driven).
        if (live.roles.sensor and live.roles.controller
                and rubric.check('controller_commands') is not None):
            try:
                live.response = drive_controller(
                    sess, obs, live.roles, lambda: _pause_sensor(state, plan, handle, sess),
                    bridge)
            except Exception as err:  # the grader's perturbation failed, not the controller
                live.response = Response(False, why='the grader failed while driving it',
                                         fault=f'{type(err).__name__}: {err}')
    finally:
        if tf is not None:
            tf.close()
        bridge.close()
        handle.shutdown(timeout=10)
    if not live.grader_fault:
        _after_the_run(state, job_dir, output)


def _watch_tf(state: JobState, sess: Session) -> TfWatch | None:
    """A tf2 listener for the `tf_tree` check, when the rubric has it (its failure is the
    grader's: the check keeps its points)."""
    if state.rubric.check('tf_tree') is None:
        return None
    from robot_lab.grading.package.tf_watch import TfWatch

    try:
        return TfWatch(sess)
    except Exception as err:  # the grader's subscription, not the student's system
        state.check_faults['tf_tree'] = f'listening on /tf failed: {type(err).__name__}: {err}'
        return None


def _process_of(statuses: list[ProcessStatus], node: str, other: str | None) -> int | None:
    """The pid of the running process that hosts `node` and not `other`: named so by the
    launch, given `__node:=` for it, or its executable named like the node."""
    import psutil

    short, other_short = node.rsplit('/', 1)[-1], (other or '').rsplit('/', 1)[-1]
    for p in statuses:
        if not p.pid or p.state != 'running' or p.name == other:
            continue
        try:
            args = psutil.Process(p.pid).cmdline()
        except psutil.Error:
            continue
        names = {a.split(':=', 1)[1] for a in args if a.startswith('__node:=')}
        exe = Path(args[0]).name if args else ''
        if len(args) > 1 and exe.startswith('python'):
            exe = Path(args[1]).name
        if (p.name == node or short in names
                or (not names and exe == short and exe != other_short)):
            return int(p.pid)
    return None


def _pause_sensor(state: JobState, plan: LaunchPlan, handle: LaunchHandle,
                  sess: Session) -> tuple[Callable[[], None], str] | None:
    """Take the student's sensor out of the loop: stop its process when it runs alone,
    else relaunch the system with the sensor's topic remapped away for that node only."""
    roles = state.live.roles
    assert roles is not None and roles.sensor and roles.sensor_topic
    pid = _process_of(handle.processes, roles.sensor, roles.controller)
    if pid is not None:
        os.kill(pid, signal.SIGSTOP)
        return (lambda: os.kill(pid, signal.SIGCONT)), "the sensor's process was paused"
    from robot_lab.graph.discovery import full_node_names
    from robot_lab.launch.api import LaunchHandle

    handle.shutdown(timeout=10)
    again = copy.deepcopy(plan)
    rule = f'{roles.sensor.rsplit("/", 1)[-1]}:{roles.sensor_topic}:=/_robot_lab_grader/unplugged'
    for spec in again.processes():
        if '--ros-args' in spec.cmd:
            spec.cmd[spec.cmd.index('--ros-args') + 1:0] = ['-r', rule]
        else:
            spec.cmd += ['--ros-args', '-r', rule]
    try:
        relaunched = LaunchHandle(again)
    except RobotLabError:
        return None
    deadline = time.monotonic() + state.rubric.startup_seconds
    while (time.monotonic() < deadline
           and roles.controller not in full_node_names(sess, include_hidden=False)):
        time.sleep(0.1)
    return ((lambda: relaunched.shutdown(timeout=10)),
            'the system was relaunched with the sensor remapped away (its process could not '
            'be paused alone)')


def _after_the_run(state: JobState, job_dir: Path, output: dict[str, list[str]]) -> None:
    """Why nodes died, what the sandbox refused, which processes outlived the launch."""
    from robot_lab.grading.package.confinement import blocked_attempts, leftover_processes
    from robot_lab.grading.package.crash import explain

    live = state.live
    assert state.package is not None
    for p in live.died():
        crash = explain(output.get(p.label, []), state.package, state.param_files)
        if crash is not None:
            live.crashes[p.label] = crash
    state.blocked += blocked_attempts((line for lines in output.values() for line in lines),
                                      job_dir)
    if os.environ.get('ROBOT_LAB_GRADE_ISOLATED'):  # in its own PID namespace: all are its
        for pid, cmdline in leftover_processes():
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
            state.blocked.append(f'a process started by the submission outlived the launch '
                                 f'(`{cmdline}`); the sandbox killed it')


def _line_rate(path: Path, seconds: float, cap: int = 256 * 1024 * 1024) -> float:
    """Lines a second a process wrote to its output (the launcher's per-process log),
    counted in chunks up to `cap` bytes: a node that floods its log at 100 kHz drowns
    /rosout for a best-effort observer, but every line reaches this file."""
    lines = 0
    try:
        with path.open('rb') as f:
            for _ in range(cap // (1 << 20)):
                chunk = f.read(1 << 20)
                if not chunk:
                    break
                lines += chunk.count(b'\n')
    except OSError:
        return 0.0
    return lines / seconds if seconds > 0 else 0.0
