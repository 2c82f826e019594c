"""Busy loops beside a benchmark: the crowded host of issue 22 (a hub with more students
than cores), made the same way in every bench that measures under load."""

from __future__ import annotations

import contextlib
import subprocess
import sys
from collections.abc import Iterator


@contextlib.contextmanager
def busy_loops(count: int) -> Iterator[list[subprocess.Popen[bytes]]]:
    """`count` processes spinning `while True: pass` for as long as the block runs."""
    loops = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
             for _ in range(count)]
    try:
        yield loops
    finally:
        for proc in loops:
            proc.kill()
            proc.wait()
