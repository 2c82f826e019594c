"""Checks of what a running system left behind: log lines, command output, plots, bags, grades."""

from __future__ import annotations

import contextlib
import math
import os
import re
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.check.base import (
    CheckError,
    callback_failed,
    judged,
    passed,
    same_value,
    wait_until,
)
from robot_lab.process import child_setup

__all__ = [
    'answer_is',
    'bag_contains',
    'command_drives',
    'command_prints',
    'first_time',
    'full_marks',
    'logs_contain',
    'no_errors',
    'plot_shows',
]


def _shown(pattern: str) -> str:
    """A pattern as a student reads it: quoted, a literal without its escapes (`[robot]`),
    a regex as written (never repr's doubled backslashes)."""
    if not re.search(r'(?<!\\)[.^$*+?{}\[\]|()]|\\\w', pattern):
        return "'" + re.sub(r'\\(.)', r'\1', pattern) + "'"
    return f"'{pattern}'"


@judged
def logs_contain(source: Any, pattern: str, timeout: float = 10.0,
                 hint: str = 'read the output above for errors (a process that died says why)'
                 ) -> None:
    """A log line matching `pattern` (regex) shows up in a launch's output or a console."""
    regex = re.compile(pattern)

    def _lines() -> list[str]:
        if hasattr(source, 'logs'):
            return list(source.logs())
        if hasattr(source, 'lines'):
            return list(source.lines(level='DEBUG'))
        raise TypeError(f'logs_contain() needs a LaunchHandle or a Console, not {source!r}')

    found = wait_until(lambda: next((line for line in _lines() if regex.search(line)), None),
                  timeout)
    if not found:
        callback_failed(f'a log line matching {_shown(pattern)}')
        tail = _lines()[-8:]
        raise CheckError(f'a log line matching {_shown(pattern)}',
                         f'no such line within {timeout:g} s' + (
                             ', the last lines are below' if tail else ', and no lines at all'),
                         hint, tail, 'The last log lines:')
    passed(f'the log shows {_shown(pattern)}')


@judged
def no_errors(launch: Any) -> None:
    """A launch's processes are all running and none logged at ERROR or FATAL."""
    errors = launch.logs(level='ERROR')
    dead = [f'{p.label} ({p.state}, exit code {p.exit_code})' for p in launch.processes
            if p.state != 'running']
    if errors or dead:
        seen = '; '.join([*(f'{d} stopped' for d in dead), *errors[-3:]])
        raise CheckError('every process running and no error messages', seen,
                         'read the first error line: it names the file and what to fix')
    passed(f'{len(launch.processes)} processes running, no error messages')


class _Terminal:
    """A bash command as typed in a terminal: its own session, its output read line by line
    as it comes (unbuffered, as a terminal gets it), stopped as Ctrl-C stops it."""

    def __init__(self, command: str, cwd: str | Path | None) -> None:
        env = {**os.environ, 'PYTHONUNBUFFERED': '1'}
        self.command = command
        self.proc = subprocess.Popen(['bash', '-c', command], cwd=cwd, env=env,
                                     stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True,
                                     start_new_session=True, preexec_fn=child_setup)
        self.lines: list[str] = []
        self.running_for: float | None = None  # s: still running when the check stopped it
        self._started = time.monotonic()
        self._before_stop = 0  # lines printed before the check's Ctrl-C (not its traceback)
        self._reader = threading.Thread(target=self._read, name='robot_lab-check-command',
                                        daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip('\n'))

    def printed(self, pattern: str) -> bool:
        return any(re.search(pattern, line) for line in list(self.lines))

    def wait_for(self, pattern: str, seconds: float) -> bool:
        """Until a line matches `pattern`, the command ends, or `seconds` pass."""
        deadline = time.monotonic() + seconds
        while not self.printed(pattern):
            if self.proc.poll() is not None:
                self._reader.join(5.0)  # the lines it printed last
                return self.printed(pattern)
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.05)
        return True

    def ended(self) -> bool:
        return self.proc.poll() is not None

    def stop(self) -> None:
        """Ctrl-C to everything it started (its output ends when they all have), then
        SIGKILL to what is left 5 s later."""
        if self.proc.poll() is None:
            self.running_for = time.monotonic() - self._started
            self._before_stop = len(self.lines)
        for sig in (signal.SIGINT, signal.SIGKILL):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.proc.pid, sig)
            self._reader.join(5.0)
            if not self._reader.is_alive():
                break
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.proc.wait(5.0)

    def not_printed(self, pattern: str) -> CheckError:
        """What the command printed instead; a command the check had to stop is judged by
        what it printed before the Ctrl-C, not by the KeyboardInterrupt that stopped it."""
        if self.running_for is None:
            lines = [line for line in self.lines if line.strip()]
            seen = f'it printed {lines[-1].strip()!r}' if lines else 'it printed nothing'
            hint = 'read the last line: it names what is missing and how to fix it'
        else:
            lines = [line for line in self.lines[:self._before_stop] if line.strip()]
            seen = (f'it was still running {self.running_for:.0f} s later, when the check '
                    'stopped it with Ctrl-C' + (f'; its last line was {lines[-1].strip()!r}'
                                                if lines else ', having printed nothing'))
            hint = ('it waits for something that never comes: is what it needs running '
                    '(a server, a publisher, in this ROS domain), and does your code get '
                    'past its wait (a spin until the future is done)?')
        return CheckError(f'`{self.command}` to print {_shown(pattern)}', seen, hint,
                          lines[-4:] if len(lines) > 1 else [], 'What it printed last:')


def _no_command(pattern: str) -> CheckError:
    return CheckError(f'a command that prints {_shown(pattern)}', 'the command is empty',
                      'write the command line in your answer cell')


@judged
def command_prints(command: str, pattern: str | Sequence[str], seconds: float = 5.0,
                   cwd: str | Path | None = None) -> None:
    """`command` (bash, as typed in a terminal) prints a line matching `pattern` within
    `seconds` (waited for no longer than that line); then it gets Ctrl-C, and everything
    it started is stopped. Several patterns: one run of the command prints them all (each
    within `seconds` of the one before), each judged on its own."""
    patterns = [pattern] if isinstance(pattern, str) else list(pattern)
    if not command.strip():
        raise _no_command(patterns[0])
    terminal = _Terminal(command, cwd)
    try:
        for each in patterns:
            if not terminal.wait_for(each, seconds):
                break
    finally:
        terminal.stop()
    for each in patterns:
        if not terminal.printed(each):
            raise terminal.not_printed(each)
        passed(f'`{command}` prints {_shown(each)}')


@judged
def command_drives(command: str, topic: str, where: Callable[[Any], bool], description: str,
                   prints: str | None = None, seconds: float = 20.0,
                   cwd: str | Path | None = None, hint: str | None = None) -> None:
    """While `command` (bash, as typed in a terminal) runs, `topic` carries a message
    `where` accepts (a pose that shows the turn): the command keeps running until one
    comes, at most `seconds` (after it printed `prints`, if given); then Ctrl-C."""
    from robot_lab.grading.check.graph import topic_publishes

    if not command.strip():
        raise _no_command(prints or description)
    terminal = _Terminal(command, cwd)
    try:
        if prints is not None:
            if not terminal.wait_for(prints, seconds):
                terminal.stop()
                raise terminal.not_printed(prints)
            passed(f'`{command}` prints {_shown(prints)}')
        try:
            topic_publishes(topic, where=where, timeout=seconds, description=description,
                            hint=hint)
        except CheckError as err:
            seen = err.seen + ('; your command had ended' if terminal.ended() else '')
            raise CheckError(f'{err.expected}, while `{command}` runs', seen, err.hint,
                             err.details, err.title) from None
    finally:
        terminal.stop()


@judged
def plot_shows(plot: Any, path: str, where: Callable[[float], bool], description: str,
               timeout: float = 5.0, last: float = 1.0) -> None:
    """The plotted values of `path` in its `last` seconds all satisfy `where` (waits)."""

    def _probe() -> list[float] | None:
        values = plot.values(path, last=last)
        return values if values and all(where(v) for v in values) else None

    values = wait_until(_probe, timeout)
    if not values:
        recent = plot.values(path, last=last)
        seen = (f'the last values were {", ".join(f"{v:.2f}" for v in recent[-5:])}'
                if recent else 'no samples arrived')
        raise CheckError(f'{path} {description}', seen,
                          'check the parameter you changed was accepted (✓ next to the slider)')
    passed(f'{path} {description}')


@judged
def bag_contains(bag: str | Path, counts: Mapping[str, int]) -> None:
    """The bag holds at least `counts[topic]` messages of each topic (`ros2 bag info`)."""
    from robot_lab.bag.info import bag_info

    try:
        info = bag_info(bag)
    except RobotLabError as err:
        raise CheckError(f'a bag at {bag}', err.message,
                         'record it first: run your `ros2 bag record … -o …` cell above') \
            from None
    have = {t.name: t.count for t in info.topics}
    short = {t: have.get(t, 0) for t, n in counts.items() if have.get(t, 0) < n}
    if short:
        absent = [t for t in short if t not in have]
        raise CheckError(
            ', '.join(f'≥ {n} messages on {t}' for t, n in counts.items()),
            'the bag has ' + ', '.join(f'{c} on {t}' for t, c in short.items()),
            f'is {", ".join(absent)} in your `ros2 bag record` line? Name every topic, '
            'separated by spaces' if absent else 'record while the nodes run, for a few seconds')
    passed('the bag holds ' + ', '.join(f'≥ {n} messages on {t}' for t, n in counts.items()))


@judged
def first_time(bag: str | Path, topic: str, field: str, where: Callable[[float], bool],
               answer: Any) -> None:
    """`answer` is the bag time (s) of the first `topic` message whose `field` satisfies
    `where`, as `robot_lab.read_topic` gives times."""
    from robot_lab.bag.read import read_topic

    columns = read_topic(bag, topic, [field])
    times = [t for t, v in zip(columns.t, columns[field], strict=True) if where(v)]
    if not times:
        raise CheckError(f'a {topic} message in the bag whose {field} matches',
                         f'none of its {len(columns)} messages does',
                         'record again, with the parameter change inside the recording; if '
                         'it was, your nodes did not act on it: notebook 04 (section 2) makes a '
                         'parameter change act at once')
    if not isinstance(answer, int | float) or not math.isclose(answer, times[0], abs_tol=1e-6):
        what = f'the bag time of the first {topic} message whose {field} matches'
        if not isinstance(answer, int | float) or isinstance(answer, bool):
            seen = f'your answer is {answer!r}, not a time in seconds'
        elif math.isclose(answer, times[-1], abs_tol=1e-6) and len(times) > 1:
            seen = f'{answer:.2f} s is the time of the last match'
        elif answer == len(times) or answer == len(columns):
            seen = f'{answer!r} is a count of messages'
        else:
            seen = f'{answer:.2f} s is not the time of the first match'
        raise CheckError(what, seen, 'take the time (`.t`) of the first message that matches, '
                                     'not the last or a count')
    passed(f'that is the time of the first {topic} message whose {field} matches')


@judged
def answer_is(name: str, answer: Any, actual: Any, hint: str, tolerance: float | None = None,
              any_order: bool = False) -> None:
    """The student's variable `name` holds `actual` (what the graph or the bag says).

    `tolerance`: relative, for measured numbers; `any_order`: lists compared as sets. A
    None answer is an answer cell that has not got past its placeholder.
    """
    if answer is None:
        raise CheckError(f'your answer in `{name}`', f'{name} is None: its answer cell has not '
                         'set it', 'replace the placeholder (raise NotImplementedError()) in the '
                         'answer cell with your code, then run that cell and this one')
    if tolerance is not None:
        right = (isinstance(answer, int | float) and not isinstance(answer, bool)
                 and abs(float(answer) - float(actual)) <= tolerance * abs(float(actual)))
        want = f'{name} within {tolerance:.0%} of {actual:.3g}' if tolerance >= 0.01 else \
            f'{name} = {actual!r}'
    else:
        given, real = answer, actual
        if any_order and isinstance(answer, list | tuple | set):
            given, real = sorted(answer), sorted(actual)
        right = same_value(given, real)
        want = f'{name} = {actual!r}'
    if not right:
        raise CheckError(want, f'you answered {answer!r}', hint)
    passed(want if tolerance is None or tolerance < 0.01 else f'{name} agrees with {actual:.3g}')


@judged
def full_marks(report: str | Path) -> None:
    """`robot-lab grade -o REPORT` gave every submission in it full marks."""
    import csv

    grades = Path(report) / 'grades.csv'
    if not grades.is_file():
        raise CheckError(f'a grade report in {Path(report).name}/', 'there is no grades.csv',
                         'run the grading cell above and read its output')
    with grades.open(newline='') as f:
        rows = list(csv.DictReader(f))
    short = [f'{r["student"]}: {r["score"]}/{r["max_score"]}' for r in rows
             if float(r['score']) < float(r['max_score'])]
    if not rows or short:
        lost = [k for r in rows for k, v in r.items()
                if k not in ('student', 'score', 'max_score') and v in ('0', '0.0')]
        raise CheckError('full marks from the grader', '; '.join(short) or 'no rows',
                         f'read the feedback of {", ".join(lost) or "each check"} above')
    passed(', '.join(f'{r["student"]}: {r["score"]}/{r["max_score"]}' for r in rows))
