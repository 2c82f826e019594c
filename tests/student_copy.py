"""What a student receives must hold no answers: no solution block, no line of an answer.

An answer line is a line between `BEGIN SOLUTION` and `END SOLUTION` in the course's
sources (solutions/, notebooks/) that appears nowhere else in them (so `import rclpy`,
which the explanations show too, is not one). A student's notebook is searched in its
cells' sources and its outputs.
"""

from __future__ import annotations

import functools
import json
import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
_BEGIN = re.compile(r'BEGIN SOLUTION')
_END = re.compile(r'END SOLUTION')


def _texts(path: Path) -> list[str]:
    """Every cell source and every text output of a notebook."""
    nb = json.loads(path.read_text())
    found = []
    for cell in nb.get('cells', []):
        found.append(''.join(cell.get('source', '')))
        for output in cell.get('outputs', []):
            found.append(''.join(output.get('text', '')))
            for value in output.get('data', {}).values():
                if isinstance(value, (str, list)):
                    found.append(''.join(value))
    return found


@functools.cache
def answer_lines(repo: Path = REPO) -> frozenset[str]:
    inside: set[str] = set()
    outside: set[str] = set()
    sources = [*sorted((repo / 'solutions').glob('*.ipynb')),
               *sorted((repo / 'notebooks').glob('*.ipynb'))]
    for path in sources:
        for text in _texts(path):
            depth = 0
            for line in text.splitlines():
                if _BEGIN.search(line):
                    depth += 1
                elif _END.search(line):
                    depth = max(0, depth - 1)
                elif line.strip():
                    (inside if depth else outside).add(line.strip())
    return frozenset(line for line in inside - outside if len(line) >= 12)


def answers_in(folder: Path) -> list[str]:
    """`file: what` for every solution block and answer line found under `folder`."""
    lines = answer_lines()
    assert len(lines) > 50, 'the course sources should hold answers to look for'
    found = []
    notebooks = sorted(folder.rglob('*.ipynb'))
    for path in notebooks:
        for text in _texts(path):
            if _BEGIN.search(text):
                found.append(f'{path}: a solution block')
            found += [f'{path}: answer line {line!r}' for line in text_lines(text) & lines]
    return found


def text_lines(text: str) -> set[str]:
    return {line.strip() for line in text.splitlines()}


def student_notebooks(folder: Path) -> list[str]:
    """The notebooks a student copy holds, relative to `folder`."""
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob('*.ipynb')
                  if '.robot_lab' not in p.parts)
