"""The running part of a package job: launch the student's system, watch it, score it.

Called by robot_lab.grading.package_checks after the build, inside the job's sandbox.
The student's launch file runs under the kit's launcher; a parameter file that rcl would
refuse is left out (so the behaviour can still be graded; `params_file` reports it) and a
package without a launch file gets every executable started (so only `launch_file` and
`params_used` are lost). The observer is this process's session in the job's domain.
"""

from __future__ import annotations

import contextlib
import math
import re
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.roles import (
    Observation,
    Roles,
    controller_output_changes,
    infer_roles,
    observe,
)

if TYPE_CHECKING:
    from robot_lab.grading.package_checks import JobState
    from robot_lab.launch.description import LaunchPlan

__all__ = ['run_live_checks']

Outcome = Callable[..., None]
Section = Callable[..., str]
Code = Callable[..., str]
_BEHAVIOUR = ('sensor_publishes', 'controller_commands', 'actuator_logs', 'params_used')


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


def _neutralise_installed_param_files(ws: Path, package: str) -> list[str]:
    """Installed parameter files rcl would refuse, replaced by an empty valid one.

    The launcher checks every file before starting anything (as rcl would refuse it in
    each node); emptied, the launch starts and the nodes run on their code defaults, so
    the behaviour is still graded while `params_file` and `params_used` report the file.
    """
    from robot_lab.errors import ParamFileError
    from robot_lab.params import load_param_file

    share = ws / 'install' / package / 'share' / package
    findings = []
    for path in sorted(share.rglob('*.y*ml')) if share.is_dir() else []:
        if path.name.endswith(('.launch.yaml', '.launch.yml')) or 'launch' in path.parts[-2:-1]:
            continue
        try:
            load_param_file(path)
        except ParamFileError as err:
            findings.append(f'{path.name}: {err}')
            real = path.resolve()  # a --symlink-install points at the source: keep that
            if real != path:
                path.unlink()
            path.write_text(_EMPTY_PARAMS)
    return findings


def _drop_bad_param_files(plan: LaunchPlan) -> list[str]:
    """Leave out parameter files rcl would refuse (the node would exit at start)."""
    from robot_lab.errors import ParamFileError
    from robot_lab.params import load_param_file

    dropped = []
    for spec in plan.processes():
        for path in list(spec.param_files):
            try:
                load_param_file(path)
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


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        with contextlib.suppress(TypeError, ValueError):
            return math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=1e-9)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def _params_used(state: JobState, plan: LaunchPlan, sess: Any, running: list[str],
                 own_files: set[str]) -> tuple[bool, str, str]:
    """(passed, observed, fix): the launch loads the student's file, nodes hold its values."""
    from robot_lab.graph.parameters import param_get
    from robot_lab.params import load_param_file

    loaded: dict[str, list[str]] = {}  # file -> node names it was given to
    for spec in plan.processes():
        for path in spec.param_files:
            if Path(path).name in own_files:
                loaded.setdefault(path, []).append(spec.node_name or spec.executable)
    if not loaded:
        return False, "the launch file passes none of the package's parameter files to a node", (
            'load it in the launch file: XML `<param from="$(find-pkg-share PKG)/config/'
            'params.yaml"/>` inside each `<node>`, Python `parameters=[os.path.join('
            "get_package_share_directory('PKG'), 'config', 'params.yaml')]`")
    checked, wrong, lines = 0, 0, []
    for path in loaded:
        data = load_param_file(path)
        for pattern, params in data.items():
            nodes = [n for n in running if _matches(pattern, n)]
            for name, value in params.items():
                held = None
                for node in nodes:
                    try:
                        held = param_get(node, name, session=sess)
                    except Exception:
                        continue
                    if held is not None:
                        break
                if not nodes or held is None:
                    lines.append(f'{pattern} {name}: no running node holds it')
                    continue
                checked += 1
                if _same(held, value):
                    lines.append(f'{node} {name} = {held!r} (file: {value!r})')
                else:
                    wrong += 1
                    lines.append(f'{node} {name} = {held!r}, but the file says {value!r}')
    passed = checked > 0 and wrong == 0
    observed = ('read back from the running nodes:\n\n' + '\n'.join(f'- `{x}`' for x in lines[:12])
                if lines else 'the file gave the nodes no parameter to check')
    fix = '' if passed else ('declare each parameter in the node (`declare_parameter(name, '
                             'default)`) and read it with `get_parameter(name).value`; make the '
                             'node names in the file match the names the launch file gives')
    return passed, observed, fix


def _last_logs(handle: Any, label: str, code: Code) -> str:
    lines = [line for line in handle.logs(label) if line.strip()][-8:]
    return code(lines, 8) if lines else ' (no output)'


def run_live_checks(job_dir: Path, ws: Path, state: JobState, outcome: Outcome,
                    section: Section, code: Code) -> None:
    """Launch, observe, score the behavioural checks (and `launch_file`)."""
    check = state.rubric.check('launch_file')
    min_nodes = int(check.option('min_nodes', 3)) if check else 3
    if not state.built:
        for path in state.launch_files:
            if (nodes := _static_launch_nodes_count(path)) >= min_nodes:
                outcome(state, 'launch_file', True, section(
                    f'a launch file starting at least {min_nodes} nodes',
                    f'`launch/{path.name}` declares {nodes} nodes (not run: the package does '
                    'not build)'))
                break
        else:
            outcome(state, 'launch_file', False, section(
                f'a launch file in launch/ starting at least {min_nodes} nodes',
                'none found' if not state.launch_files else 'the launch files declare fewer',
                'add launch/<name>.launch.xml (or .launch.py) with one node entry per node'))
        for cid in _BEHAVIOUR:
            outcome(state, cid, False, section('the running system', 'not run: the package '
                                               'does not build (see "builds")', 'fix the build'))
        return
    from robot_lab.pkg.workspace import use_workspace

    saved_path = list(sys.path)
    use_workspace(ws)
    sys.path[:] = saved_path  # the student's modules stay out of the grader
    emptied = _neutralise_installed_param_files(ws, state.package_name)
    plan, launch_name, notes = _plan_for(state, job_dir)
    if plan is None:
        for cid in ('launch_file', *_BEHAVIOUR):
            outcome(state, cid, False, section(
                'a launch file that starts the nodes', 'no launch file could be run and the '
                'package installs no executables' + ''.join(f'\n\n{n}' for n in notes),
                'add entry_points console_scripts in setup.py and launch/<name>.launch.xml'))
        return
    dropped = emptied + _drop_bad_param_files(plan)
    _observe_and_score(job_dir, state, plan, launch_name, notes, dropped, min_nodes,
                       outcome, section, code)


def _static_launch_nodes_count(path: Path) -> int:
    """How many nodes a launch file declares, read as text (for a package that does not
    build, so the file cannot be resolved)."""
    text = path.read_text(errors='replace')
    if path.suffix == '.xml':
        return len(re.findall(r'<node\b', text))
    if path.suffix in ('.yaml', '.yml'):
        return len(re.findall(r'^\s*-?\s*node\s*:', text, re.MULTILINE))
    return len(re.findall(r'\bNode\s*\(', text))


def _observe_and_score(job_dir: Path, state: JobState, plan: LaunchPlan, launch_name: str,
                       notes: list[str], dropped: list[str], min_nodes: int,
                       outcome: Outcome, section: Section, code: Code) -> None:
    from robot_lab.context import session
    from robot_lab.graph.view import graph_view
    from robot_lab.launch.api import LaunchHandle

    rubric = state.rubric
    sess = session()
    try:
        launched = time.monotonic()
        handle = LaunchHandle(plan)
    except RobotLabError as err:
        for cid in ('launch_file', *_BEHAVIOUR):
            outcome(state, cid, False, section(
                'a launch file the launcher can start', f'the launch did not start: {err}',
                err.fix or 'run it yourself with `ros2 launch` and fix the error it prints'))
        return
    try:
        obs = observe(sess, len(plan.processes()), rubric.startup_seconds,
                      rubric.observe_seconds, alive=lambda: handle.running)
        running = [n for n in obs.nodes]
        with contextlib.suppress(Exception):
            state.images.append(graph_view(session=sess).save(job_dir / 'graph.png'))
        own = {p.name for p in state.param_files}
        params = _params_used(state, plan, sess, running, own)
        statuses = handle.processes
        logs = {p.label: _last_logs(handle, p.label, code) for p in statuses}
        line_rates = {p.name: _line_rate(handle.log_dir / f'{p.label}.log',
                                         time.monotonic() - launched) for p in statuses}
    finally:
        handle.shutdown(timeout=10)
    # launch_file
    started = [p for p in statuses if p.pid is not None]
    lines = [f'- `{p.label}` ({p.name}): {p.state}'
             + (f', exit code {p.exit_code}' if p.exit_code not in (None, 0) else '')
             for p in statuses]
    observed = (f'`launch/{launch_name}` started {len(started)} process(es):\n\n'
                if launch_name else 'no launch file was run.\n\n') + '\n'.join(lines)
    if notes:
        observed += '\n\n' + '\n\n'.join(notes)
    ok = bool(launch_name) and len(started) >= min_nodes
    outcome(state, 'launch_file', ok, section(
        f'a launch file in launch/ that starts all (at least {min_nodes}) nodes', observed,
        '' if ok else 'add every node to the launch file (and install launch/ with data_files)'))
    roles = infer_roles(obs, float(_opt(state, 'sensor_publishes', 'min_rate_hz', 0.5)))
    _score_roles(state, obs, roles, statuses, logs, line_rates, outcome, section, code)
    passed, observed, fix = params
    if dropped:
        observed += ('\n\nleft out of the launch (rcl would refuse them, and every node '
                     'given them would exit at start):\n\n') + '\n'.join(
            f'- {d}' for d in dropped)
        fix = 'make the parameter file valid first (see the parameter file check)'
    outcome(state, 'params_used', passed, section(
        'the launch file loads the parameter file and the running nodes hold its values',
        observed, fix))


def _opt(state: JobState, check_id: str, key: str, default: Any) -> Any:
    check = state.rubric.check(check_id)
    return check.option(key, default) if check else default


def _topics_seen(obs: Observation) -> str:
    rows = [f'- `{t.name}` [{", ".join(t.types)}] {t.count} msgs ({t.rate:.1f} Hz); '
            f'published by {", ".join(t.publishers) or "-"}, '
            f'subscribed by {", ".join(t.subscribers) or "-"}'
            for t in sorted(obs.topics.values(), key=lambda t: t.name)][:12]
    return 'topics seen:\n\n' + ('\n'.join(rows) if rows else '(none)')


def _label_of(statuses: list[Any], node: str | None) -> str | None:
    return next((p.label for p in statuses if node and p.name == node), None)


def _dead(statuses: list[Any], code: Code, logs: dict[str, str]) -> str:
    died = [p for p in statuses if p.state == 'died' or p.exit_code not in (None, 0)]
    return ''.join(f'\n\n`{p.label}` exited with code {p.exit_code}; its last output:'
                   f'{logs.get(p.label, "")}' for p in died)


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


def _score_roles(state: JobState, obs: Observation, roles: Roles, statuses: list[Any],
                 logs: dict[str, str], line_rates: dict[str, float], outcome: Outcome,
                 section: Section, code: Code) -> None:
    min_rate = float(_opt(state, 'sensor_publishes', 'min_rate_hz', 0.5))
    max_logs = float(_opt(state, 'sensor_publishes', 'max_log_rate_hz', 500))
    seen = _topics_seen(obs) + _dead(statuses, code, logs)
    # Sensor.
    if roles.sensor is None:
        outcome(state, 'sensor_publishes', False, section(
            f'a node that publishes a topic periodically (≥ {min_rate:g} Hz) without input',
            seen, 'create a timer (`create_timer(1.0 / rate, callback)`) that publishes a '
            'message with a simulated reading'))
        return _no_controller(state, obs, roles, seen, outcome, section)
    topic = obs.topics[roles.sensor_topic or '']
    sample = topic.samples[-1] if topic.samples else '(none kept)'
    flood = max(obs.log_rate(roles.sensor), line_rates.get(roles.sensor, 0.0))
    ok = flood <= max_logs
    outcome(state, 'sensor_publishes', ok, section(
        f'a node that publishes a topic periodically without input, logging at most '
        f'{max_logs:g} lines/s', f'sensor `{roles.sensor}` publishes `{topic.name}` '
        f'[{", ".join(topic.types)}] at {topic.rate:.1f} Hz; sample: `{sample}`'
        + ('' if ok else f'\n\nbut it logs {flood:.0f} lines/s; last lines:'
           + code(list(obs.nodes[roles.sensor].logs), 4)),
        '' if ok else 'log at DEBUG, or throttle (`throttle_duration_sec=` on the logger), and '
        'never print in a loop'))
    if roles.controller is None:
        return _no_controller(state, obs, roles, seen, outcome, section)
    commands = obs.topics.get(roles.command_topic or '')
    count = commands.count if commands else 0
    sample = commands.samples[-1] if commands and commands.samples else '(none)'
    changes = controller_output_changes(obs, roles)
    need_change = bool(_opt(state, 'controller_commands', 'require_change', False))
    ok = count > 0 and (changes or not need_change)
    outcome(state, 'controller_commands', ok, section(
        'a node that subscribes to the sensor topic and publishes commands derived from it',
        f'controller `{roles.controller}` subscribes to `{roles.sensor_topic}` and publishes '
        f'`{roles.command_topic}`: {count} msgs in {obs.duration:.1f} s; sample: `{sample}`'
        + ('' if changes else '; every command was the same'),
        '' if ok else 'publish a command in the sensor callback (or a timer) computed from '
        'the latest reading'))
    # Actuator.
    if roles.actuator is None:
        outcome(state, 'actuator_logs', False, section(
            f'a node that subscribes to `{roles.command_topic}` and logs each command',
            'no other node subscribes to it.\n\n' + seen,
            f'subscribe to `{roles.command_topic}` with the same type and call '
            '`self.get_logger().info(...)` in the callback'))
        return None
    node = obs.nodes[roles.actuator]
    fraction = float(_opt(state, 'actuator_logs', 'min_log_fraction', 0.5))
    ok = count > 0 and node.log_count >= max(1.0, fraction * count)
    outcome(state, 'actuator_logs', ok, section(
        f'a node that subscribes to `{roles.command_topic}` and logs each command',
        f'actuator `{roles.actuator}` received {count} commands and logged {node.log_count} '
        'lines; its last log lines:' + (code(list(node.logs), 5) if node.logs else ' (none)')
        + _dead(statuses, code, logs),
        '' if ok else 'call `self.get_logger().info(f"...{msg}")` in the subscription callback'))
    return None


def _no_controller(state: JobState, obs: Observation, roles: Roles, seen: str,
                   outcome: Outcome, section: Section) -> None:
    why = '; '.join(roles.notes) or 'no node subscribes to a sensor topic and publishes'
    outcome(state, 'controller_commands', False, section(
        'a node that subscribes to the sensor topic and publishes commands derived from it',
        why + '.\n\n' + seen,
        "subscribe to exactly the sensor's topic name and type (check with `ros2 topic "
        'list -t`), and publish a command from the callback'))
    outcome(state, 'actuator_logs', False, section(
        'a node that subscribes to the commands and logs each one',
        'no commands to log: there is no controller output.\n\n' + seen,
        'first make the controller publish commands'))
