"""The instructor's copy of an exercise, and how a submitted notebook is held to it.

A submission is graded only against a known exercise (a notebook in the solutions folder):
its name comes from the notebook's metadata, else its file name; a notebook that names an
unknown exercise, or none, is refused, never graded by its own check cells. Every locked
cell (nbgrader `locked` or `grade`, matched by grade_id, else by cell id) is replaced by
the instructor's, so editing a check, stripping its metadata or duplicating it changes
nothing; a check cell that is missing scores 0.

A check is judged by its own execution, not by what the kernel printed: the cell that
runs is the instructor's source behind a fresh import of the checking helpers from the
kit's own files (a student cell that patched `robot_lab.grading.check` patched a module
the check no longer uses), followed by a line that prints a random token. The check
passed only if the token came (so the check ran to its end), the kernel's reply says
`ok` (an exception handler that swallows errors still leaves an `error` reply) and no
error was shown. The token is fresh for every check of every run.

What this cannot stop: a student cell runs in the same Python process as the check, so
code written against this grader could still forge a pass: reading the next cell's source
(and its token) from a pre-run hook, or patching what a check calls besides the helpers
(`robot_lab.graph`, rclpy, `math.isclose`). Read the executed notebooks (`--executed`)
of surprising scores.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from nbformat import NotebookNode

from robot_lab.errors import RobotLabError
from robot_lab.grading.exercises import Check, grade_id, graded_checks, kit_root, read_notebook

__all__ = ['AnswerKey', 'identify', 'judge', 'known_exercises', 'student_of']

_CHECK_HELPERS = Path(__file__).resolve().parents[1] / 'check'  # the package's folder
_ANSI = re.compile(r'\x1b\[[0-9;]*m')
_OUTPUT_LIMIT = 2000  # characters of a check's printed lines kept for feedback
_NBGRADER_FOLDERS = ('submitted', 'autograded')  # an nbgrader course's student folders


def solutions_folder(solutions_dir: str | Path | None) -> Path:
    return Path(solutions_dir) if solutions_dir is not None else kit_root() / 'solutions'


def known_exercises(solutions_dir: str | Path | None = None) -> list[str]:
    """The exercises an instructor's copy exists for (solutions/*.ipynb)."""
    return sorted(p.stem for p in solutions_folder(solutions_dir).glob('*.ipynb'))


def identify(path: str | Path, nb: NotebookNode, solutions_dir: str | Path | None = None) -> str:
    """The known exercise a submission is, or RobotLabError saying why it is refused."""
    known = known_exercises(solutions_dir)
    where = Path(path)
    fix = ('submit the notebook as it was handed out (known exercises: '
           f'{", ".join(known) or "none"}); to grade other exercises, pass --solutions DIR')
    named = nb.get('metadata', {}).get('robot_lab', {}).get('exercise')
    if isinstance(named, str) and named:
        if named in known:
            return named
        raise RobotLabError(f'refused: its metadata names exercise {named!r}, which is not a '
                            'known exercise', file=where, fix=fix)
    matches = [name for name in known if name in where.stem]
    if not matches:
        raise RobotLabError('refused: it matches no known exercise (none named in its '
                            'metadata or its file name)', file=where, fix=fix)
    return max(matches, key=len)


def student_of(path: str | Path, exercise: str) -> str:
    """Who handed `path` in: the rest of the file name, else the folder it sits in.

    `alice_ex04_parameters.ipynb`, Canvas's `doejane_12345_67890_ex04_parameters.ipynb`,
    `alice/ex04_parameters.ipynb`, nbgrader's `submitted/alice/ex04/ex04_parameters.ipynb`
    and Moodle's `Jane Doe_123_assignsubmission_file_/ex04_parameters.ipynb` all work.
    """
    # The LMS download layouts are recognised where package submissions are.
    from robot_lab.grading.package.submission import student_of as entry_student

    def student_name(name: str) -> str:
        return entry_student(Path(name))

    file = Path(path)
    stem = file.stem
    if stem != exercise and exercise in stem:
        canvas = student_name(stem)
        if canvas != stem:
            return canvas
        rest = stem.replace(exercise, ' ').strip(' _-.')
        if rest:
            return rest
    parts = file.resolve().parts
    for index in range(len(parts) - 3, -1, -1):
        if parts[index] in _NBGRADER_FOLDERS:  # <folder>/<student>/<assignment>/<notebook>
            return parts[index + 1]
    folder = file.resolve().parent
    return student_name(folder.name) if folder.name else stem


@dataclass(frozen=True)
class AnswerKey:
    """An exercise's instructor copy: its checks, and every cell a student may not change."""

    exercise: str
    path: Path
    checks: list[Check]
    locked: dict[str, NotebookNode]  # grade_id -> the instructor's cell

    @classmethod
    def load(cls, exercise: str, solutions_dir: str | Path | None = None) -> AnswerKey:
        path = solutions_folder(solutions_dir) / f'{exercise}.ipynb'
        nb = read_notebook(path)
        locked = {}
        for cell in nb.cells:
            meta = cell.get('metadata', {}).get('nbgrader', {})
            name = grade_id(cell)
            if name and cell.cell_type == 'code' and (meta.get('locked') or (
                    meta.get('grade') and not meta.get('solution'))):
                locked[name] = cell
        return cls(exercise, path, graded_checks(nb, str(path)), locked)

    def impose(self, nb: NotebookNode) -> dict[str, int]:
        """Put the instructor's locked cells into `nb`; where each check now is (index)."""
        placed: dict[str, int] = {}
        for index, cell in enumerate(nb.cells):
            key = grade_id(cell) or str(cell.get('id', ''))
            if key in self.locked and key not in placed:
                fresh = copy.deepcopy(self.locked[key])
                fresh['outputs'], fresh['execution_count'] = [], None
                nb.cells[index] = fresh
                placed[key] = index
            elif 'nbgrader' in cell.get('metadata', {}):
                # A second copy, or a check of the student's own: it runs, it never counts.
                del cell.metadata['nbgrader']
        return {c.cell_id: placed[c.cell_id] for c in self.checks if c.cell_id in placed}

    @staticmethod
    def guarded(check: Check, token: str) -> str:
        """The code run for `check`: fresh helpers, the instructor's source, then the token."""
        from IPython.core.inputtransformer2 import TransformerManager

        body = TransformerManager().transform_cell(check.source)
        # Every module of the check package is dropped and read again from the kit's folder:
        # the package goes into sys.modules first, so its imports of its own modules load
        # them afresh from that folder instead of taking what a student cell patched.
        name, folder = 'robot_lab.grading.check', str(_CHECK_HELPERS)
        return (
            'import importlib.util as _rl_util, sys as _rl_sys, robot_lab.grading as _rl_pkg\n'
            f'_rl_stale = [n for n in _rl_sys.modules if (n + ".").startswith({name + "."!r})]\n'
            '_rl_gone = [_rl_sys.modules.pop(n) for n in _rl_stale]\n'
            f'_rl_spec = _rl_util.spec_from_file_location({name!r}, '
            f'{folder + "/__init__.py"!r}, submodule_search_locations=[{folder!r}])\n'
            'check = _rl_util.module_from_spec(_rl_spec)\n'
            f'_rl_sys.modules[{name!r}] = check\n'
            '_rl_spec.loader.exec_module(check)\n'
            '_rl_pkg.check = check\n'
            'del _rl_util, _rl_spec, _rl_sys, _rl_pkg, _rl_stale, _rl_gone\n'
            f'{body}\n'
            f'print({token!r})\n'
        )


def _stdout(cell: NotebookNode) -> str:
    return ''.join(str(o.get('text', '')) for o in cell.get('outputs', [])
                   if o.get('output_type') == 'stream')


def error_of(cell: NotebookNode) -> str | None:
    """`Name: message` of the error a cell showed, if it showed one."""
    for output in cell.get('outputs', []):
        if output.get('output_type') == 'error':
            value = _ANSI.sub('', str(output.get('evalue', ''))).strip()
            name = str(output.get('ename', 'Error'))
            return f'{name}: {value}' if value else name
    return None


def judge(cell: NotebookNode, token: str, reply: dict[str, Any] | None) -> str | None:
    """None when the check ran to its end and passed, else why it did not.

    Also removes the token from the cell's output, so the executed notebook reads clean.
    """
    came = False
    for output in cell.get('outputs', []):
        if output.get('output_type') == 'stream' and token in str(output.get('text', '')):
            came = True
            output['text'] = '\n'.join(line for line in str(output['text']).split('\n')
                                       if line != token)
    cell['outputs'] = [o for o in cell.get('outputs', [])
                       if o.get('output_type') != 'stream' or o.get('text')]
    shown = error_of(cell)
    if shown:
        return shown
    content = (reply or {}).get('content', {})
    if content.get('status') != 'ok':
        name, value = content.get('ename'), _ANSI.sub('', str(content.get('evalue', ''))).strip()
        if name:
            return f'{name}: {value}' if value else str(name)
        return 'the check did not finish'
    if not came:
        return 'the check did not finish (its result never came)'
    return None


def check_output(cell: NotebookNode) -> str:
    """The lines a check printed (its ✓ lines), bounded, for feedback."""
    text = _ANSI.sub('', _stdout(cell)).strip()
    return text if len(text) <= _OUTPUT_LIMIT else text[:_OUTPUT_LIMIT] + ' …'
