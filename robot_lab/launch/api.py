"""`robot_lab.launch(...)` for notebooks: a launch running beside the kernel, as a handle.

The supervisor runs in a background thread of the kernel (the thread its children's
parent-death signal is tied to), so the cell returns at once. Running the same launch
again replaces the previous one: a re-run cell never doubles the nodes. Nothing outlives
the kernel: an orderly exit stops every launch (atexit), a crash or restart kills the
children through their parent-death signal.
"""

from __future__ import annotations

import atexit
import html
import re
import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

from robot_lab.errors import LaunchError
from robot_lab.launch.output import LaunchOutput, OutputLine
from robot_lab.launch.parameters import check_param_files
from robot_lab.launch.plan import LaunchPlan
from robot_lab.launch.runner import run_supervisor
from robot_lab.launch.supervisor import Supervisor

__all__ = ['LaunchHandle', 'ProcessStatus', 'describe_launch', 'launch', 'running_launches']

_SEVERITY = {'DEBUG': 10, 'INFO': 20, 'WARN': 30, 'WARNING': 30, 'ERROR': 40, 'FATAL': 50,
             'CRITICAL': 50}
_LIGHTS = {'running': '#2e7d32', 'respawning': '#f9a825', 'finished': '#9e9e9e',
           'died': '#c62828', 'pending': '#90caf9'}

_REGISTRY: dict[str, LaunchHandle] = {}
_REGISTRY_LOCK = threading.Lock()


def describe_launch(source: str | Path, file: str | None = None,
                    args: Mapping[str, str] | None = None) -> LaunchPlan:
    """The resolved plan of a launch file, nothing started (see robot_lab.launch.resolve)."""
    from robot_lab.launch.resolve import describe_launch as resolve

    return resolve(source, file, args)


@dataclass(frozen=True)
class ProcessStatus:
    """One process of a launch as it is now."""

    name: str  # the node's full name (`/sensor`), or the label for a plain executable
    label: str  # `sensor_node-1`, as the output prefixes it
    pid: int | None
    state: str  # 'pending' | 'running' | 'finished' | 'died' | 'respawning'
    exit_code: int | None


class LaunchHandle:
    """A running launch: its processes, its output, and the way to stop it."""

    def __init__(self, plan: LaunchPlan, *, key: str | None = None,
                 start_timeout: float = 30.0) -> None:
        self.plan = plan
        self.key = key if key is not None else str(Path(plan.source).resolve())
        self.output = LaunchOutput(None, log_dir=plan.log_dir)
        self.returncode: int | None = None
        self._error: BaseException | None = None
        self._supervisor = Supervisor(plan, self.output, noninteractive=True)
        self._thread = threading.Thread(
            target=self._run, name=f'robot_lab-launch-{Path(plan.source).name}', daemon=True)
        self._thread.start()
        if not self._supervisor.started.wait(start_timeout):
            self.shutdown()
            raise LaunchError(f'the launch did not start within {start_timeout} s',
                              file=plan.source)
        if self._error is not None:
            raise LaunchError(f'the launch failed to start: {self._error}',
                              file=plan.source) from self._error

    def _run(self) -> None:
        # This thread forks the children and must live as long as they do.
        try:
            self.returncode = run_supervisor(self._supervisor)
        except BaseException as exc:  # reported by .processes/.wait_for, not lost in a thread
            self._error = exc
            self._supervisor.started.set()

    @property
    def running(self) -> bool:
        """True until every process of the launch has ended."""
        return self._thread.is_alive()

    @property
    def log_dir(self) -> Path:
        return self.output.log_dir

    @property
    def processes(self) -> list[ProcessStatus]:
        """Every process of the plan with its pid, state and exit code."""
        return [
            ProcessStatus(r.name, r.label, r.pid, r.state, r.returncode)
            for r in self._supervisor.records
        ]

    def logs(self, node: str | None = None, level: str | None = None) -> list[str]:
        """Output lines, optionally of one node/process and at least a severity.

        `node` matches a label (`sensor_node-1`), an executable (`sensor_node`) or a node
        name (`sensor`, `/sensor`); `level` ('INFO', 'WARN', ...) keeps lines that are log
        records of that severity or above.
        """
        minimum = None
        if level is not None:
            minimum = _SEVERITY.get(level.upper())
            if minimum is None:
                raise ValueError(
                    f'unknown log level {level!r}; use one of DEBUG INFO WARN ERROR FATAL')
        return [line.text for line in self.output.lines()
                if self._matches(line, node) and _at_least(line, minimum)]

    def _matches(self, line: OutputLine, node: str | None) -> bool:
        if node is None:
            return True
        wanted = node.lstrip('/')
        if line.source == wanted or line.logger == wanted.replace('/', '.'):
            return True
        for record in self._supervisor.records:
            if record.label != line.source:
                continue
            names = {record.spec.executable, record.label.rsplit('-', 1)[0]}
            if record.spec.node_name:
                names.add(record.spec.node_name.lstrip('/'))
            return wanted in names
        return False

    def wait_for(self, pattern: str, timeout: float = 10.0) -> re.Match[str]:
        """Block until an output line matches `pattern` (a regex); its match.

        Raises LaunchError with the last lines when nothing matched in time or the launch
        ended first.
        """
        regex = re.compile(pattern)
        deadline = time.monotonic() + timeout
        seen = 0
        while True:
            lines, seen = self.output.since(seen)
            for line in lines:
                found = regex.search(line.text)
                if found:
                    return found
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not self.running:
                break
            self.output.wait(seen, min(remaining, 0.5))
        last = '\n'.join(line.text for line in self.output.lines()[-20:])
        why = 'the launch ended' if not self.running else f'nothing matched within {timeout} s'
        raise LaunchError(f'no output line matched {pattern!r}: {why}; last lines:\n{last}')

    def shutdown(self, timeout: float = 15.0) -> None:
        """Stop every process (SIGINT, then SIGTERM, then SIGKILL) and wait for the end."""
        self._supervisor.shutdown('shutdown() called')
        self._thread.join(timeout)
        with _REGISTRY_LOCK:
            if _REGISTRY.get(self.key) is self:
                del _REGISTRY[self.key]

    def __enter__(self) -> LaunchHandle:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.shutdown()

    def __repr__(self) -> str:
        states = ', '.join(f'{p.label}: {p.state}' for p in self.processes)
        return f'<LaunchHandle {Path(self.plan.source).name} ({states})>'

    def _repr_html_(self) -> str:
        rows = []
        for p in self.processes:
            colour = _LIGHTS.get(p.state, '#9e9e9e')
            light = (f'<span style="display:inline-block;width:0.8em;height:0.8em;'
                     f'border-radius:50%;background:{colour}" title="{p.state}"></span>')
            code = '' if p.exit_code is None else str(p.exit_code)
            cells = [light, html.escape(p.label), html.escape(p.name),
                     '' if p.pid is None else str(p.pid), p.state, code]
            rows.append('<tr>' + ''.join(f'<td>{c}</td>' for c in cells) + '</tr>')
        titles = ('', 'process', 'name', 'pid', 'state', 'exit code')
        head = ''.join(f'<th>{h}</th>' for h in titles)
        title = html.escape(str(self.plan.source))
        return (f'<div><b>launch</b> <code>{title}</code>'
                f'<table><thead><tr>{head}</tr></thead><tbody>{"".join(rows)}</tbody></table></div>')


def _at_least(line: OutputLine, minimum: int | None) -> bool:
    if minimum is None:
        return True
    return line.level is not None and _SEVERITY.get(line.level, 0) >= minimum


def _launch_value(value: object) -> str:
    if isinstance(value, bool):
        return 'true' if value else 'false'
    return str(value)


def launch(pkg_or_path: str | Path, file: str | None = None, **args: object) -> LaunchHandle:
    """Start a launch file beside the kernel; a re-run replaces the previous same launch.

    `robot_lab.launch('robot_lab', 'robot.launch.xml', robot_name='alpha')` is
    `ros2 launch robot_lab robot.launch.xml robot_name:=alpha`. Errors (bad file, bad
    parameter file, unknown package) raise before anything starts.
    """
    plan = describe_launch(pkg_or_path, file, {k: _launch_value(v) for k, v in args.items()})
    check_param_files(plan)
    key = str(Path(plan.source).resolve())
    with _REGISTRY_LOCK:
        previous = _REGISTRY.pop(key, None)
    if previous is not None:
        previous.shutdown()
    handle = LaunchHandle(plan, key=key)
    with _REGISTRY_LOCK:
        _REGISTRY[key] = handle
    return handle


def running_launches() -> list[LaunchHandle]:
    """The launches this process started that are still running."""
    with _REGISTRY_LOCK:
        return [h for h in _REGISTRY.values() if h.running]


@atexit.register
def _shutdown_all() -> None:
    with _REGISTRY_LOCK:
        handles = list(_REGISTRY.values())
    for handle in handles:
        handle.shutdown(timeout=12.0)
