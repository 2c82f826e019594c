"""`colcon build` for a workspace: the real colcon from the venv, with progress and the
error lines that matter when a package fails (not colcon's whole log).

colcon prints `Starting >>> pkg` / `Finished <<< pkg` / `Failed <<< pkg`; everything a
package's build writes in between (setup.py tracebacks go straight to colcon's stderr)
is kept per package, together with log/latest_build/<pkg>/stderr.log, and boiled down
to the user's traceback or the `error:` lines.
"""

from __future__ import annotations

import html
import os
import re
import subprocess
import sys
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robot_lab.env import ros_environment
from robot_lab.errors import PackageError
from robot_lab.pkg.index import kit_prefix
from robot_lab.process import spawn, stop

__all__ = ['BuildResult', 'build', 'colcon_executable', 'error_lines', 'package_dirs']

_ORDER_ITEM = re.compile(r'^- (?P<pkg>\S+) \((?P<type>[^)]+)\)$')
_STARTING = re.compile(r'^Starting >>> (?P<pkg>\S+)')
_FINISHED = re.compile(r'^Finished <<< (?P<pkg>\S+)')
_FAILED = re.compile(r'^Failed\s+<<< (?P<pkg>\S+)')
_ABORTED = re.compile(r'^Aborted\s+<<< (?P<pkg>\S+)')
_COLCON_LOG = re.compile(r'^\[\d+\.\d+s\] ')
# Frames of the build machinery, not of the student's package.
_MACHINERY = re.compile(r'/(colcon_\w+|asyncio|setuptools|distutils|_distutils|subprocess\.py)')
_STRING_FRAME = re.compile(r'^  File "<string>", line (?P<line>\d+)(?P<rest>.*)$')
_MAX_LINES = 25
_SKIP_DIRS = {'build', 'install', 'log', '.git', '__pycache__'}


def colcon_executable() -> Path:
    """The venv's colcon (the one installed with the kit), never another on PATH."""
    path = Path(sys.prefix) / 'bin' / 'colcon'
    if not path.is_file():
        raise PackageError(
            f'colcon is not installed in this environment ({path} is missing)',
            fix="pip install 'robot_lab[kit]' (it brings colcon-core and colcon-ros)",
        )
    return path


@dataclass
class BuildResult:
    """What a `colcon build` did: which packages built or failed, and why."""

    workspace: Path
    command: list[str]
    returncode: int = 0
    packages: dict[str, str] = field(default_factory=dict)  # name -> colcon's package type
    finished: list[str] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)
    errors: dict[str, list[str]] = field(default_factory=dict)
    hints: dict[str, list[str]] = field(default_factory=dict)
    summary: list[str] = field(default_factory=list)
    output: list[str] = field(default_factory=list)
    duration: float = 0.0

    @property
    def ok(self) -> bool:
        return self.returncode == 0 and not self.failed

    def report_lines(self) -> list[str]:
        """The failing packages with their error lines and hints, then colcon's summary."""
        lines: list[str] = []
        for pkg in self.failed:
            lines.append(f'--- {pkg} failed ---')
            lines.extend(self.errors.get(pkg, []))
            lines.extend(f'hint: {hint}' for hint in self.hints.get(pkg, []))
        logged = [pkg for pkg in self.failed if pkg != 'colcon']
        if logged:
            lines.append(f'(full log: {self.workspace / "log" / "latest_build" / logged[0]})')
        if not self.packages and self.ok and '--packages-select' not in self.command:
            lines.append(
                f'no packages found below {self.workspace}: put them in src/ '
                '(robot-lab pkg create --destination-directory src NAME)'
            )
        lines.extend(self.summary)
        return lines

    def __str__(self) -> str:
        return '\n'.join(self.report_lines())

    def _repr_html_(self) -> str:
        colour = '#1a7f37' if self.ok else '#cf222e'
        head = 'build finished' if self.ok else 'build failed: ' + ', '.join(self.failed)
        body = html.escape(str(self))
        return (
            f'<div><b style="color:{colour}">{html.escape(head)}</b> '
            f'({self.duration:.1f}s, {len(self.finished)} finished)'
            f'<pre style="white-space:pre-wrap">{body}</pre></div>'
        )


def _traceback_blocks(lines: Sequence[str]) -> Iterator[list[str]]:
    """Each Python traceback in `lines`: header, frames, exception line(s)."""
    i = 0
    while i < len(lines):
        if lines[i].startswith('Traceback (most recent call last):'):
            block = [lines[i]]
            i += 1
            while i < len(lines) and (lines[i].startswith(' ') or not lines[i].strip()):
                block.append(lines[i])
                i += 1
            if i < len(lines):
                block.append(lines[i])  # the exception line
            yield block
        i += 1


def _user_frames(block: list[str], setup_py: Path | None) -> list[str]:
    """Drop the frames that belong to colcon/setuptools; keep the student's.

    colcon runs setup.py through `run_setup`, which execs its text: those frames say
    `File "<string>"`; they are named after the package's setup.py again here.
    """
    kept = [block[0]]
    skip = False
    after_run_setup = False
    for line in block[1:-1]:
        if line.startswith('  File '):
            if 'run_setup' in line or 'exec(code' in line:
                after_run_setup = True
            skip = bool(_MACHINERY.search(line))
            string = _STRING_FRAME.match(line)
            if string is not None:
                if not after_run_setup or setup_py is None:
                    skip = True  # colcon's own `python -c ...`
                else:
                    number = int(string['line'])
                    kept.append(f'  File "{setup_py}", line {number}{string["rest"]}')
                    source = setup_py.read_text(errors='replace').splitlines()
                    if 0 < number <= len(source):
                        kept.append('    ' + source[number - 1].strip())
                    skip = True
                    continue
        elif 'exec(code' in line:
            after_run_setup = True
        if not skip and line.strip():
            kept.append(line)
    kept.append(block[-1])
    return kept


def error_lines(
    console: Sequence[str], stderr_log: Sequence[str] = (), setup_py: Path | None = None
) -> list[str]:
    """The lines that explain a package's failure, from its build output and stderr.log."""
    every = [line for line in [*console, *stderr_log] if not _COLCON_LOG.match(line)]
    picked: list[str] = []
    for block in _traceback_blocks(every):
        if 'CalledProcessError' in block[-1] or 'colcon' in block[-1]:
            continue  # colcon reporting that setup.py failed: the cause is elsewhere
        frames = _user_frames(block, setup_py)
        if frames not in [picked[i:i + len(frames)] for i in range(len(picked))]:
            picked.extend(frames)
    for line in every:
        low = line.lower()
        if (low.startswith(('error', 'cmake error', 'fatal')) or ': error:' in low) \
                and line not in picked:
            picked.append(line)
    if not picked:
        picked = [line for line in every if line.strip()][-_MAX_LINES:]
    return picked[:_MAX_LINES]


def package_dirs(root: Path) -> dict[str, Path]:
    """Package name -> source folder, found as colcon crawls (COLCON_IGNORE respected)."""
    found: dict[str, Path] = {}

    def crawl(folder: Path) -> None:
        if (folder / 'COLCON_IGNORE').exists():
            return
        xml = folder / 'package.xml'
        if xml.is_file():
            m = re.search(r'<name>\s*([^<\s]+)\s*</name>', xml.read_text(errors='replace'))
            found.setdefault(m.group(1) if m else folder.name, folder)
            return
        for child in sorted(folder.iterdir()):
            if child.is_dir() and child.name not in _SKIP_DIRS and not child.name.startswith('.'):
                crawl(child)

    crawl(root)
    return found


def _hints(source: Path | None, pkg: str, pkg_type: str, lines: Iterable[str]) -> list[str]:
    hints: list[str] = []
    text = '\n'.join(lines)
    if pkg_type in ('ros.catkin', 'ros.ament_cmake', 'ros.cmake', 'cmake'):
        hints.append(
            f'colcon built {pkg} as a CMake package ({pkg_type}): its package.xml has no '
            '<export><build_type>ament_python</build_type></export>; add it '
            '(robot-lab doctor shows where)'
        )
    if '/opt/python/' in text or "No 'rosidl_typesupport_c' found" in text:
        hints.append(
            "the ROS wheels' CMake files are not set up for this machine: run "
            '`robot-lab build --kit` once, then `source "$VIRTUAL_ENV/setup.bash"`'
        )
    if 'No module named' in text or 'package directory' in text:
        hints.append(
            f'check that {pkg}/{pkg}/__init__.py exists and setup.py lists the package'
        )
    if source is not None:
        hints.append(f'robot-lab doctor {source} checks the package files')
    return hints


def _progress_bar(total: int) -> Any:
    """tqdm in a terminal or notebook; None when output is piped (plain lines instead)."""
    in_notebook = 'ipykernel' in sys.modules
    if not (in_notebook or sys.stderr.isatty()):
        return None
    try:
        if in_notebook:
            from tqdm.auto import tqdm
        else:
            from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total or None, unit='pkg', desc='colcon build', leave=True)


def build(
    workspace: str | os.PathLike[str] = '.',
    packages_select: Sequence[str] | None = None,
    symlink_install: bool = False,
    progress: bool = True,
) -> BuildResult:
    """Run `colcon build` in `workspace` and report what built, what failed and why."""
    root = Path(workspace).expanduser().resolve()
    if not root.is_dir():
        raise PackageError(
            f'workspace {root} does not exist', fix='create it with mkdir -p WORKSPACE/src'
        )
    if (root / 'package.xml').is_file():
        raise PackageError(
            f'{root} is a package, not a workspace', file=root / 'package.xml',
            fix=f'build from the workspace that holds it: robot-lab build {root.parent.parent}',
        )
    cmd = [
        str(colcon_executable()), 'build',
        '--event-handlers', 'console_stderr-', 'console_package_list+',
    ]
    if symlink_install:
        cmd.append('--symlink-install')
    if packages_select:
        cmd += ['--packages-select', *packages_select]
    result = BuildResult(workspace=root, command=cmd)
    started = time.monotonic()
    env = ros_environment()
    # colcon warns about every AMENT_PREFIX_PATH entry without colcon's setup files; the
    # kit's editable prefix is one and no build needs it. The venv has them once the kit
    # packages are built (kit_packages.install_underlay), and rosidl needs it there.
    own = {str(p) for p in (kit_prefix(), Path(sys.prefix))
           if p is not None and not (p / 'local_setup.sh').is_file()}
    env['AMENT_PREFIX_PATH'] = os.pathsep.join(
        p for p in env.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p and p not in own
    )
    proc = spawn(cmd, env=env, cwd=root, stdout=subprocess.PIPE,
                 stderr=subprocess.STDOUT)
    bar: Any = None
    current: str | None = None
    per_package: dict[str, list[str]] = {}
    in_summary = False
    assert proc.stdout is not None
    try:
        for raw in iter(proc.stdout.readline, b''):
            line = raw.decode(errors='replace').rstrip('\n')
            result.output.append(line)
            item = _ORDER_ITEM.match(line)
            if item and not result.finished and current is None:
                result.packages[item['pkg']] = item['type']
                continue
            if line == 'Topological order':
                continue
            if line.startswith('Summary:'):
                in_summary = True
            if in_summary:
                if line.strip():
                    result.summary.append(line)
                continue
            if (m := _STARTING.match(line)) is not None:
                current = m['pkg']
                if progress and bar is None:
                    bar = _progress_bar(len(result.packages))
                if bar is not None:
                    bar.set_postfix_str(current)
                elif progress:
                    print(line, flush=True)
                continue
            done = _FINISHED.match(line) or _FAILED.match(line) or _ABORTED.match(line)
            if done is not None:
                pkg = done['pkg']
                (result.finished if line.startswith('Finished') else result.failed).append(pkg)
                if bar is not None:
                    bar.update(1)
                    bar.write(line)
                elif progress:
                    print(line, flush=True)
                current = None
                continue
            if current is not None:
                per_package.setdefault(current, []).append(line)
    except KeyboardInterrupt:
        stop(proc)
        raise
    finally:
        if bar is not None:
            bar.close()
    result.returncode = proc.wait()
    result.duration = time.monotonic() - started
    sources = package_dirs(root) if result.failed else {}
    for pkg in result.failed:
        log = root / 'log' / 'latest_build' / pkg / 'stderr.log'
        logged = log.read_text(errors='replace').splitlines() if log.is_file() else []
        lines = per_package.get(pkg, [])
        setup_py = sources[pkg] / 'setup.py' if pkg in sources else None
        result.errors[pkg] = error_lines(lines, logged, setup_py)
        hints = _hints(sources.get(pkg), pkg, result.packages.get(pkg, ''), [*lines, *logged])
        if hints:
            result.hints[pkg] = hints
    unknown = [pkg for pkg in packages_select or () if pkg not in result.packages]
    if unknown:
        # colcon silently skips them; a typo should not look like a successful build.
        have = ', '.join(sorted(package_dirs(root))) or 'none'
        result.errors['colcon'] = [
            f"--packages-select: no package named {', '.join(map(repr, unknown))} "
            f'in {root} (packages found: {have})'
        ]
        result.failed.append('colcon')
    if result.returncode != 0 and not result.failed:
        # colcon itself refused (bad arguments, unknown package in --packages-select).
        result.errors['colcon'] = [line for line in result.output if line.strip()][-_MAX_LINES:]
        result.failed.append('colcon')
    if result.ok:
        from robot_lab.pkg.workspace import refresh_workspace

        refresh_workspace(root)
    return result
