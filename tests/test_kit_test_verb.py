"""`./kit test PATH…` runs what it names, with the suite's layout; the notebooks run as chains.

Before, `./kit test notebooks` (or a test file) ran the whole suite as well: the default
targets were always passed. And nbval's notebooks ran as one group on one worker, though
only lessons 01-06 build on each other.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from conftest import _group

from robot_lab.grading.course import first_of_chain

pytestmark = pytest.mark.no_ros
ROOT = Path(__file__).resolve().parents[1]


def _collected(*args: str) -> list[str]:
    """The node ids `./kit test ARGS --co` would run."""
    done = subprocess.run([str(ROOT / 'kit'), 'test', *args, '--co', '-q', '-n', '0'],
                          cwd=ROOT, capture_output=True, text=True, timeout=240, check=False)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return [line for line in done.stdout.splitlines() if '::' in line]


def test_named_paths_replace_the_default_targets() -> None:
    notebooks = _collected('notebooks')
    assert notebooks and all(item.startswith('notebooks/') for item in notebooks), notebooks[:5]
    names = {item.split('::', 1)[0] for item in notebooks}
    assert names == {f'notebooks/{p.name}' for p in (ROOT / 'notebooks').glob('*.ipynb')}
    one = _collected('tests/test_kit_test_verb.py')
    assert one and all(item.startswith('tests/test_kit_test_verb.py::') for item in one), one


def test_lessons_01_to_06_are_one_group_and_the_others_stand_alone() -> None:
    groups: dict[str, list[int]] = {}
    for path in sorted((ROOT / 'notebooks').glob('*.ipynb')):
        number = int(re.match(r'\d+', path.name).group())  # type: ignore[union-attr]
        groups.setdefault(_group(f'notebooks/{path.name}::Cell 0'), []).append(number)
    assert sorted(groups.values()) == [[0], [1, 2, 3, 4, 5, 6], [7], [8], [9], [10], [11],
                                       [12], [13]], groups
    assert first_of_chain('04_parameters') == 1 and first_of_chain('07_capstone') == 7
