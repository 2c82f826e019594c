"""Why a student's node died, told from its own source: the last frame in their package,
the exception, and the fix for that cause.

A traceback from a job runs through the kit's and Python's files (`…/site-packages/rclpy/…`)
and the installed copy of the student's module (`install/<pkg>/lib/python3.x/site-packages/
<pkg>/node.py`); the student knows `<pkg>/node.py` in their package. `explain()` finds the
last frame that is theirs, quotes its line from their source, and picks the fix from the
exception: a module named by a `console_scripts` entry that does not exist → `setup.py`; a
parameter of the wrong type → the parameter file's line; a syntax error → that line.
`public_text()` strips every internal path from feedback.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from pathlib import Path

__all__ = ['Crash', 'explain', 'public_text']

_LABEL = re.compile(r'^\[[\w.-]+-\d+\] ')  # the launcher's '[controller_node-2] '
_FRAME = re.compile(r'File "([^"]+)", line (\d+)')
_EXCEPTION = re.compile(r'^([A-Za-z_][\w.]*(?:Error|Exception|Exit|Interrupt|Warning))\b:?\s*(.*)$')
_ENTRY = re.compile(r"""['"]\s*([\w.-]+)\s*=\s*([\w.]+)\s*:\s*(\w+)\s*['"]""")
_SITE = re.compile(r'(?:[^\s"\'`(]*/)?install/[^/\s]+/lib/python3\.\d+/site-packages/')
_ANY_SITE = re.compile(r'/[^\s"\'`(]*/(?:site|dist)-packages/')
_STDLIB = re.compile(r'/[^\s"\'`(]*/lib/python3\.\d+/')


@dataclass
class Crash:
    """A node's death as its author should read it."""

    exception: str  # 'ModuleNotFoundError: No module named robot_system.controler'
    where: str = ''  # 'robot_system/controller_node.py line 12', '' when no frame is theirs
    code: str = ''  # that line of their source
    fix: str = ''

    def markdown(self) -> str:
        text = f'`{self.exception}`'
        if self.where:
            text += f' at {self.where}' + (f': `{self.code}`' if self.code else '')
        return text


def public_text(text: str, job_dir: Path | None = None) -> str:
    """Feedback text without grader paths: the job folder, the install tree, the venv."""
    if job_dir is not None:
        for prefix in (f'{job_dir.resolve()}/ws/src/', f'{job_dir}/ws/src/',
                       f'{job_dir.resolve()}/ws/', f'{job_dir}/ws/',
                       f'{job_dir.resolve()}/', f'{job_dir}/'):
            text = text.replace(prefix, '')
    text = _SITE.sub('', text)
    text = _ANY_SITE.sub('', text)
    text = _STDLIB.sub('', text)
    return text.replace(sys.prefix + '/', '')


def _student_file(path: str, package: Path) -> Path | None:
    """The student's source file a traceback path stands for, if it is theirs."""
    for marker in ('/site-packages/', f'/src/{package.name}/', f'/build/{package.name}/'):
        if marker in path:
            rel = path.split(marker, 1)[1]
            candidate = package / rel
            if candidate.is_file():
                return candidate
    candidate = Path(path)
    if candidate.is_file() and candidate.resolve().is_relative_to(package.resolve()):
        return candidate
    return None


def _last_traceback(lines: list[str]) -> list[str]:
    start = max((i for i, line in enumerate(lines) if 'Traceback (most recent call last)' in line),
                default=None)
    if start is None:  # a SyntaxError before any code ran prints no 'Traceback' line
        start = max((i for i, line in enumerate(lines) if _FRAME.search(line)), default=None)
        if start is None:
            return []
    return lines[start:]


def _setup_entry(package: Path, module: str) -> tuple[int, str, str] | None:
    """(line, entry text, its module) of a console_scripts entry naming `module`."""
    setup = package / 'setup.py'
    if not setup.is_file():
        return None
    for number, line in enumerate(setup.read_text(errors='replace').splitlines(), 1):
        for match in _ENTRY.finditer(line):
            target = match.group(2)
            if target == module or target.startswith(module + '.') or module.startswith(target):
                return number, match.group(0).strip('\'" '), target
    return None


def _modules(package: Path) -> list[str]:
    return sorted(f'{p.parent.name}.{p.stem}' for p in package.glob('*/*.py')
                  if p.name != '__init__.py' and p.parent.name not in ('test', 'launch'))


def _param_line(param_files: list[Path], name: str, package: Path) -> str:
    leaf = name.rsplit('.', 1)[-1]
    pattern = re.compile(rf'^\s*{re.escape(leaf)}\s*:\s*(.+?)\s*$')
    for path in param_files:
        for number, line in enumerate(path.read_text(errors='replace').splitlines(), 1):
            if pattern.match(line):
                return f'{path.relative_to(package)} line {number}: `{line.strip()}`'
    return ''


def _fix(kind: str, message: str, package: Path, param_files: list[Path]) -> str:
    if kind in ('ModuleNotFoundError', 'ImportError'):
        found = re.search(r"No module named '?([\w.]+)'?", message)
        module = found.group(1) if found else ''
        entry = _setup_entry(package, module) if module else None
        if entry is not None:
            number, text, target = entry
            return (f'setup.py line {number}: the entry point `{text}` names the module '
                    f'`{target}`, which is not in your package (it has: '
                    f'{", ".join(_modules(package)) or "no modules"}); correct the name in '
                    'setup.py and rebuild')
        return (f'`{module}` is not part of your package or its dependencies: fix the import, '
                'or add the package that provides it to package.xml (`<exec_depend>`)')
    if kind.endswith(('InvalidParameterTypeException', 'InvalidParameterValueException',
                      'ParameterUninitializedException')):
        found = re.search(r"parameter '([^']+)'", message)
        name = found.group(1) if found else ''
        expects = re.search(r"expecting type '?(\w+)", message)
        where = _param_line(param_files, name, package) if name else ''
        return ((f'{where} — ' if where else '') + f'give `{name}` a value of the type the '
                'node declares' + (f' ({expects.group(1)})' if expects else '')
                + ': a number without quotes, `true`/`false`, or a string in quotes')
    if kind in ('SyntaxError', 'IndentationError', 'TabError'):
        return ('fix the syntax on that line (check with `python3 -m py_compile <file>`), then '
                'run the node yourself with `ros2 run` before handing in')
    return ('fix the error on that line; run the node yourself with `ros2 run <package> '
            '<executable>` to see it happen')


def explain(lines: list[str], package: Path, param_files: list[Path]) -> Crash | None:
    """The crash a process's output shows (its last traceback), or None."""
    block = _last_traceback([_LABEL.sub('', line, count=1) for line in lines])
    if not block:
        return None
    exception_line = next((line.strip() for line in reversed(block)
                           if _EXCEPTION.match(line.strip())), '')
    if not exception_line:
        return None
    match = _EXCEPTION.match(exception_line)
    assert match is not None
    kind = match.group(1).rsplit('.', 1)[-1]
    crash = Crash(public_text(exception_line)[:300],
                  fix=_fix(kind, match.group(2), package, param_files))
    for line in reversed(block):
        frame = _FRAME.search(line)
        if frame is None:
            continue
        source = _student_file(frame.group(1), package)
        if source is None:
            continue
        number = int(frame.group(2))
        crash.where = f'`{source.relative_to(package)}` line {number}'
        text = source.read_text(errors='replace').splitlines()
        crash.code = text[number - 1].strip()[:200] if 0 < number <= len(text) else ''
        break
    return crash
