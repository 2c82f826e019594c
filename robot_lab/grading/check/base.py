"""What every check shares: the error a failing check raises, its ✓ line, a bounded wait."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

__all__ = [
    'CheckError',
    'eventually',
    'passed',
    'same_value',
    'wait_until',
]


class CheckError(AssertionError):
    """A check cell's expectation did not hold; the message says what to try."""

    def __init__(self, expected: str, seen: str, hint: str) -> None:
        self.expected, self.seen, self.hint = expected, seen, hint
        super().__init__(f'✗ expected {expected}; {seen}. Try: {hint}')


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


def eventually(condition: Callable[[], Any], what: str, timeout: float = 5.0,
               hint: str = 'run the cells above again, in order') -> None:
    """`condition()` becomes truthy within `timeout` s."""
    value = wait_until(condition, timeout)
    if not value:
        raise CheckError(what, f'still not true after {timeout:g} s', hint)
    passed(what)
