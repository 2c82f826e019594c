"""What every check shares: the error a failing check raises, its ✓ line, a bounded wait.

A failing check is one `✗ expected …; observed …` line and one `Try: …` line: CheckError
renders itself that way in IPython (`_render_traceback_`), without the kit's frames, and
the cell still ends in an error, so nbval, nbgrader's validate and autograde see it fail.
When the student's own code raised, the student's frames follow, and only those.

Every check first closes what earlier runs of its cell started (robot_lab.notebook_cell),
so a re-run judges the current answer alone.
"""

from __future__ import annotations

import functools
import math
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any, ParamSpec, TypeVar

from robot_lab.notebook_cell import new_run, outside_the_kit
from robot_lab.shared_memory import deaf_note

__all__ = [
    'CheckError',
    'callback_failed',
    'eventually',
    'judged',
    'outside_the_kit',
    'passed',
    'same_value',
    'student_frames',
    'wait_until',
]

P = ParamSpec('P')
R = TypeVar('R')

_RED, _BOLD, _RESET = '\x1b[31m', '\x1b[1m', '\x1b[0m'


class CheckError(AssertionError):
    """A check cell's expectation did not hold; the message says what to try.

    `details` (the student's frames, the last log lines) are shown under the two lines,
    after `title`; the message itself (what graders record) stays one line.
    """

    def __init__(self, expected: str, seen: str, hint: str, details: list[str] | None = None,
                 title: str = 'Where in your code (most recent call last):') -> None:
        self.expected, self.seen, self.hint = expected, seen, hint
        self.details, self.title = list(details or []), title
        super().__init__(f'✗ expected {expected}; observed {seen}. Try: {hint}')

    def _render_traceback_(self) -> list[str]:
        """What IPython shows for this error: two lines, then the details (no kit frames)."""
        shown = [f'{_RED}✗ expected {self.expected}; observed {self.seen}{_RESET}',
                 f'{_BOLD}Try:{_RESET} {self.hint}']
        if self.details:
            shown += ['', self.title, *self.details]
        return shown


def student_frames(err: BaseException, mine: Callable[[str], bool]) -> list[str]:
    """The frames of `err`'s traceback in files `mine` accepts, formatted (source lines too)."""
    frames = [f for f in traceback.extract_tb(err.__traceback__) if mine(f.filename)]
    lines = [f'  {Path(f.filename).name}, line {f.lineno}, in {f.name}'
             + (f'\n    {f.line.strip()}' if f.line else '') for f in frames]
    text = f'{type(err).__name__}' + (f': {err}' if str(err) else '')
    return [*lines, text] if lines else []


def callback_failed(what: str) -> None:
    """Raise CheckError if a node started in this kernel raised in a callback (a timer's, a
    subscription's): that exception, at the student's line, is why nothing came."""
    from robot_lab.rclpy_session import session

    errors = session().callback_errors
    while errors:
        err = errors.pop()
        if err is None:
            continue
        mine = [f for f in traceback.extract_tb(err.__traceback__) if outside_the_kit(f.filename)]
        if mine:
            errors.clear()
            text = type(err).__name__ + (f': {err}' if str(err) else '')
            raise CheckError(what, f'your node stopped: its callback {mine[-1].name}() raised '
                             f'{text} at {Path(mine[-1].filename).name} line {mine[-1].lineno}',
                             'fix that line in your answer cell, run the cell, then this check '
                             'again', student_frames(err, outside_the_kit))


def judged(check: Callable[P, R]) -> Callable[P, R]:
    """A check: it first closes what earlier runs of the executing cell started. When it
    fails in a process that no longer hears new participants (Fast DDS took over its
    shared-memory port: robot_lab.shared_memory.lost_ports), that is what to fix, not the
    student's code."""

    @functools.wraps(check)
    def run(*args: P.args, **kwargs: P.kwargs) -> R:
        new_run()
        try:
            return check(*args, **kwargs)
        except CheckError as err:
            if not (note := deaf_note()):
                raise
            raise CheckError(err.expected, err.seen, note, err.details, err.title) from None

    return run


def passed(text: str) -> None:
    """The one deterministic line a check prints when it holds (nbval compares it)."""
    print(f'✓ {text}')


def wait_until(probe: Callable[[], Any], timeout: float, interval: float = 0.1) -> Any:
    """Poll `probe` until it returns something truthy or `timeout` passes (then its last)."""
    deadline = time.monotonic() + timeout
    while True:
        value = probe()
        if value or time.monotonic() >= deadline:
            return value
        time.sleep(interval)


def same_value(a: Any, b: Any) -> bool:
    """Equal, floats within a tolerance (a parameter read back is a float of its own)."""
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=1e-9)
        except (TypeError, ValueError):
            return False
    return bool(a == b)


@judged
def eventually(condition: Callable[[], Any], what: str, timeout: float = 5.0,
               hint: str = 'run the cells above again, in order', seen: str | None = None
               ) -> None:
    """`condition()` becomes truthy within `timeout` s (0: holds now).

    `seen` says what is there instead; without it the failure says only that it is not so.
    """
    value = wait_until(condition, timeout)
    if not value:
        if seen is None:
            seen = 'it is not so' if timeout <= 0 else f'still not so after {timeout:g} s'
        raise CheckError(what, seen, hint)
    passed(what)
