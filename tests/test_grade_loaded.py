"""Under load, the same grades (issue 51, item 6): a small class graded at `--jobs 2` on a
quiet host and again beside three busy loops (more runnable processes than cores, as on a
crowded hub) gets the same score in every check of every row. The class covers a full
row (an independent student's package), a partial one (the actuator dies at start) and a
mostly failing one (setup.py does not parse: nothing builds); the whole of class_ch6 and
class_independent quiet against loaded is a command, its numbers in the closing note."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest
from conftest import REPO, run_cli

DATA = REPO / 'tests' / 'data'
pytestmark = pytest.mark.timeout(900)


def _make_class(root: Path) -> Path:
    from test_grade_package import _actuator_crash, _setup_syntax

    shutil.copytree(DATA / 'class_independent' / 'kofi', root / 'kofi')
    for name, fault in (('actuator_crash', _actuator_crash), ('setup_syntax', _setup_syntax)):
        shutil.copytree(DATA / 'class_ch6' / 'reference', root / name)
        fault(root / name)
    return root


def _grades(out: Path) -> dict[str, dict[str, str]]:
    with (out / 'grades.csv').open() as f:
        return {row['student']: row for row in csv.DictReader(f)}


def _grade(root: Path, out: Path) -> dict[str, dict[str, str]]:
    done = run_cli('grade', str(root), '--lab', 'ch6-lab1', '-o', str(out), '--jobs', '2',
                   timeout=800)
    assert done.returncode == 0, done.stdout + done.stderr
    return _grades(out)


@pytest.fixture
def busy_loops() -> Iterator[list[psutil.Process]]:
    """Three processes spinning for as long as the test needs them (one more than cores
    on the 2-core CI host, beside the grader's two jobs)."""
    loops = [subprocess.Popen([sys.executable, '-c', 'while True: pass']) for _ in range(3)]
    try:
        yield [psutil.Process(p.pid) for p in loops]
    finally:
        for proc in loops:
            proc.kill()
            proc.wait()


def test_grades_beside_busy_loops_equal_the_quiet_run(
        tmp_path: Path, busy_loops: list[psutil.Process]) -> None:
    root = _make_class(tmp_path / 'class')
    for loop in busy_loops:
        loop.suspend()  # the quiet run first
    quiet = _grade(root, tmp_path / 'quiet')
    spun = [loop.cpu_times().user for loop in busy_loops]
    for loop in busy_loops:
        loop.resume()
    loaded = _grade(root, tmp_path / 'loaded')
    assert all(loop.is_running() and loop.cpu_times().user > before + 1.0
               for loop, before in zip(busy_loops, spun, strict=True)), 'the loops never ran'

    scores = {s: f"{row['score']}/{row['max_score']}" for s, row in quiet.items()}
    assert scores == {'kofi': '13/13', 'actuator_crash': '10/13', 'setup_syntax': '4/13'}
    differ = {(student, check): (value, loaded[student][check])
              for student, row in quiet.items() for check, value in row.items()
              if loaded.get(student, {}).get(check) != value}
    assert set(loaded) == set(quiet)
    assert differ == {}, ('graded beside 3 busy loops, not every score equals the quiet run '
                          f'(quiet, loaded): {differ}'
                          + ''.join(_feedback(tmp_path, s) for s in {s for s, _ in differ}))


def _feedback(runs: Path, student: str) -> str:
    """What each run told the student (without the graph picture)."""
    text = ''
    for run in ('quiet', 'loaded'):
        page = (runs / run / 'feedback' / f'{student}.md').read_text()
        lines = [line for line in page.splitlines() if 'base64' not in line]
        text += f'\n--- {student}, {run} ---\n' + '\n'.join(lines)
    return text
