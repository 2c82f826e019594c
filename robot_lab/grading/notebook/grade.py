"""Grade a submitted notebook: run it headless, score its check cells, leave nothing behind.

The submission runs top to bottom in a fresh kernel of this venv (nbclient), in a scratch
folder that is also its ROBOT_LAB_WORKSPACE, so student packages never land in the kit.
It is graded against the instructor's copy of its exercise only (robot_lab.grading
.answer_key: locked and check cells restored by grade_id, each check judged by its own
execution); a notebook of no known exercise is refused. A check that fails
scores 0 with its error; a cell that hangs is interrupted after `cell_timeout` s; a kernel
that dies or stops answering ends the run with the checks not reached at 0. Every
process the kernel started carries a token in its environment and is killed at the end
if it outlived the kernel.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from nbformat import NotebookNode

from robot_lab.errors import RobotLabError
from robot_lab.grading.exercises import notebook_text, read_notebook
from robot_lab.grading.notebook.answer_key import (
    AnswerKey,
    check_output,
    identify,
    judge,
    student_of,
)

if TYPE_CHECKING:
    import psutil
    from jupyter_client.manager import KernelManager

__all__ = [
    'CheckResult',
    'GradeResult',
    'grade',
    'leftover_processes',
    'submissions',
]

TOKEN_VAR = 'ROBOT_LAB_GRADE_RUN'
_KERNEL = 'robot_lab_grade'
_GRACE = 10.0  # after an interrupt, how long a cell has to stop before the kernel is killed
_DOMAIN_BASES = ('ROBOT_LAB_TEST_DOMAIN_BASE', 'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE')


@dataclass
class CheckResult:
    """The score of one check cell."""

    check: str  # the cell id
    points: float
    max_points: float
    passed: bool
    message: str = ''  # why it failed
    output: str = ''  # what it printed (its ✓ lines), bounded


@dataclass
class GradeResult:
    """A graded submission: per-check scores, total, and how the run ended."""

    notebook: str
    exercise: str
    student: str = ''
    checks: list[CheckResult] = field(default_factory=list)
    status: str = 'completed'  # 'completed' | 'timeout' | 'kernel died' | 'error'
    detail: str = ''
    elapsed: float = 0.0
    leftovers: list[str] = field(default_factory=list)  # outlived the kernel, were killed
    domain: int | None = None  # the ROS_DOMAIN_ID it ran in

    @property
    def score(self) -> float:
        return sum(c.points for c in self.checks)

    @property
    def max_score(self) -> float:
        return sum(c.max_points for c in self.checks)

    def summary(self) -> str:
        """`ex02_write_nodes: 7/10`, the line a gradebook script greps for."""
        if self.status == 'error' and not self.checks:
            return f'{self.exercise}: not graded'
        return f'{self.exercise}: {_number(self.score)}/{_number(self.max_score)}'

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data['score'] = self.score
        data['max_score'] = self.max_score
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> GradeResult:
        """The result back from `to_dict()` (e.g. a child grader's JSON)."""
        fields = {k: v for k, v in data.items() if k not in ('checks', 'score', 'max_score')}
        return cls(**fields, checks=[CheckResult(**c) for c in data.get('checks', [])])

    def table(self) -> str:
        """The per-check table the CLI prints, then the summary line."""
        if self.status == 'error' and not self.checks:
            return f'{self.notebook}: not graded: ' + self.detail.removeprefix(
                f'{self.notebook}: ')
        width = max([len(c.check) for c in self.checks] + [5])
        lines = [f'{self.notebook}', f'  {"check":<{width}}  points  result']
        for c in self.checks:
            pts = f'{_number(c.points)}/{_number(c.max_points)}'
            result = 'ok' if c.passed else c.message or 'failed'
            lines.append(f'  {c.check:<{width}}  {pts:>6}  {result}')
        if self.status != 'completed':
            lines.append(f'  run ended early ({self.status}): {self.detail}')
        if self.leftovers:
            lines.append(f'  killed {len(self.leftovers)} process(es) left running: '
                         + ', '.join(self.leftovers))
        lines.append(self.summary())
        return '\n'.join(lines)


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else f'{value:g}'


def submissions(paths: list[str | Path]) -> list[Path]:
    """Notebooks to grade: files as given, folders expanded to their *.ipynb (sorted)."""
    found: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            found.extend(sorted(p for p in path.rglob('*.ipynb')
                                if not p.name.endswith('.graded.ipynb')
                                and not any(part.startswith('.')
                                            for part in p.relative_to(path).parts)))
        elif path.is_file():
            found.append(path)
        else:
            raise RobotLabError('no such submission', file=path,
                                fix='give a .ipynb file or a folder of them')
    return found


def _kernel_spec_dir(work: Path) -> Path:
    """A kernelspec for this venv's Python, so no other installed 'python3' is used."""
    folder = work / 'kernels' / _KERNEL
    folder.mkdir(parents=True)
    spec = {
        'argv': [sys.executable, '-m', 'ipykernel_launcher', '-f', '{connection_file}'],
        'display_name': 'robot_lab (grading)',
        'language': 'python',
    }
    (folder / 'kernel.json').write_text(json.dumps(spec))
    return work / 'kernels'


def leftover_processes(token: str) -> list[psutil.Process]:
    """Running processes whose environment carries `token` (psutil.Process objects)."""
    import psutil

    found = []
    for proc in psutil.process_iter():
        with contextlib.suppress(psutil.Error):
            if proc.environ().get(TOKEN_VAR) == token:
                found.append(proc)
    return found


def _describe(proc: psutil.Process) -> str:
    import psutil

    try:
        cmd = proc.cmdline()
    except psutil.Error:
        return f'pid {proc.pid}'
    exe = next((Path(part).name for part in cmd[1:] if not part.startswith('-')), '')
    return f'{Path(cmd[0]).name if cmd else "?"} {exe} (pid {proc.pid})'.replace('  ', ' ')


def _reap(token: str, known: list[psutil.Process], grace: float = 1.0) -> list[str]:
    """Wait for the kernel's processes to die with it; kill and name the ones that do not."""
    import psutil

    procs = {p.pid: p for p in [*known, *leftover_processes(token)]}
    _gone, alive = psutil.wait_procs(list(procs.values()), timeout=grace)
    names = [_describe(p) for p in alive]
    for proc in alive:
        with contextlib.suppress(psutil.Error):
            proc.kill()
    psutil.wait_procs(alive, timeout=grace)
    return names


@contextlib.contextmanager
def _scratch(workspace: str | Path | None) -> Iterator[Path]:
    if workspace is not None:
        path = Path(workspace)
        path.mkdir(parents=True, exist_ok=True)
        yield path
        return
    with tempfile.TemporaryDirectory(prefix='robot_lab_grade_') as tmp:
        yield Path(tmp)


def grade(
    submission: str | Path,
    *,
    cell_timeout: float = 60.0,
    solutions_dir: str | Path | None = None,
    workspace: str | Path | None = None,
    executed: str | Path | None = None,
    domain_id: int | None = None,
    total_timeout: float | None = 900.0,
) -> GradeResult:
    """Run `submission` headless and score its check cells.

    `workspace` is the scratch folder given to the notebook (default: a new temporary
    one, removed afterwards); `executed`, if given, receives the notebook with outputs;
    `domain_id` is the kernel's ROS_DOMAIN_ID (default: this process's). No cell runs
    longer than `cell_timeout` s, and the whole notebook no longer than `total_timeout` s.
    """
    from nbclient import NotebookClient
    from nbclient.exceptions import DeadKernelError

    path = Path(submission)
    try:
        nb = read_notebook(path)
    except (OSError, ValueError) as err:
        raise RobotLabError(f'cannot read the notebook: {err}', file=path,
                            fix='submit the .ipynb file as Jupyter saved it') from None
    exercise = identify(path, nb, solutions_dir)
    key = AnswerKey.load(exercise, solutions_dir)
    checks = key.checks
    at = key.impose(nb)  # check id -> cell index
    by_index = {index: c for c in checks for cid, index in at.items() if cid == c.cell_id}
    result = GradeResult(str(path), exercise, student_of(path, exercise))
    outcome: dict[str, str | None] = {}  # check id -> None (passed) or the reason it failed
    token = uuid.uuid4().hex
    replies: dict[int, dict[str, Any]] = {}

    def on_executed(cell: NotebookNode, cell_index: int, execute_reply: Any) -> None:
        replies[cell_index] = dict(execute_reply or {})
    started = time.monotonic()
    known: list[psutil.Process] = []
    with _scratch(workspace) as work, tempfile.TemporaryDirectory(prefix='robot_lab_kernel_') as k:
        from jupyter_client.kernelspec import KernelSpecManager
        from jupyter_client.manager import AsyncKernelManager

        from robot_lab.env import ros_environment

        specs = KernelSpecManager(kernel_dirs=[str(_kernel_spec_dir(Path(k)))])
        # Unix sockets in this job's folder, not TCP ports: a free port chosen here can be
        # taken by another grader's kernel before this one binds it ("Address already in
        # use", seen in a CI run with four graders at once).
        km = AsyncKernelManager(kernel_name=_KERNEL, kernel_spec_manager=specs,
                                transport='ipc', connection_file=str(Path(k) / 'kernel.json'))
        client = NotebookClient(
            nb, km=km, kernel_name=_KERNEL, timeout=None, allow_errors=True,
            interrupt_on_timeout=False, shutdown_kernel='graceful', record_timing=False,
            resources={'metadata': {'path': str(work)}}, on_cell_executed=on_executed,
        )
        env = ros_environment({TOKEN_VAR: token, 'ROBOT_LAB_WORKSPACE': str(work),
                               'MPLBACKEND': 'Agg'})
        if domain_id is not None:
            env['ROS_DOMAIN_ID'] = str(domain_id)
        result.domain = int(env['ROS_DOMAIN_ID'])
        # The grader picks the domain: lesson set-up must not move the kernel elsewhere.
        for name in _DOMAIN_BASES:
            env.pop(name, None)
        current = -1
        watchdog: _Watchdog | None = None
        log_path = Path(k) / 'kernel.log'
        try:
            with log_path.open('wb') as log, client.setup_kernel(
                    env=env, stdout=log, stderr=log, cleanup_kc=True):
                known = _kernel_tree(km)
                deadline = None if total_timeout is None else started + total_timeout
                for current, cell in enumerate(nb.cells):
                    if cell.cell_type != 'code':
                        continue
                    budget = cell_timeout
                    if deadline is not None:
                        budget = min(budget, deadline - time.monotonic())
                        if budget <= 0:
                            result.status = 'timeout'
                            result.detail = (f'the notebook ran past {_number(total_timeout or 0)}'
                                             f' s in total, before cell {current}')
                            break
                    check = by_index.get(current)
                    nonce = uuid.uuid4().hex
                    if check is not None:
                        cell.source = AnswerKey.guarded(check, nonce)
                    try:
                        with _Watchdog(km, budget, min(cell_timeout, _GRACE)) as watchdog:
                            client.execute_cell(cell, current)
                    finally:
                        if check is not None:
                            cell.source = check.source
                    known = _kernel_tree(km, known)
                    if check is not None:
                        outcome[check.cell_id] = (
                            f'timed out after {budget:.3g} s (interrupted)'
                            if watchdog.interrupted
                            else judge(cell, nonce, replies.get(current)))
        except DeadKernelError:
            if watchdog is not None and watchdog.killed:
                result.status = 'timeout'
                result.detail = (f'cell {current} ran past {watchdog.timeout:.3g} s and did not '
                                 'stop when interrupted; the kernel was killed')
                why = f'timed out after {watchdog.timeout:.3g} s (kernel killed)'
            else:
                result.status = 'kernel died'
                result.detail = f'the kernel died while running cell {current}'
                why = 'the kernel died running this cell'
            if current in by_index:
                outcome[by_index[current].cell_id] = why
        except RuntimeError as err:  # the kernel did not start
            result.status = 'error'
            result.detail = f'the kernel did not start: {err}'
        finally:
            result.leftovers = _reap(token, known)
        if result.status != 'completed':
            result.detail += _log_tail(log_path)
        if executed is not None:
            Path(executed).write_text(notebook_text(nb))
    for check in checks:
        if check.cell_id not in outcome:
            why = 'check cell missing from the submission' if check.cell_id not in at else \
                f'not run ({result.status})'
            result.checks.append(CheckResult(check.cell_id, 0, check.points, False, why))
            continue
        error = outcome[check.cell_id]
        passed = error is None
        result.checks.append(CheckResult(check.cell_id, check.points if passed else 0,
                                         check.points, passed, _public(error or '', work),
                                         _public(check_output(nb.cells[at[check.cell_id]]),
                                                 work)))
    result.elapsed = round(time.monotonic() - started, 2)
    return result


def _public(text: str, work: Path) -> str:
    """`text` with the paths the student knows: the grader's scratch folder is their
    workspace (~/robot_lab_ws), the grader's home is `~`."""
    text = text.replace(str(work), '~/robot_lab_ws')
    home = str(Path.home())
    return text.replace(home + '/', '~/') if home != '/' else text


def _log_tail(path: Path, lines: int = 5) -> str:
    """The end of the kernel's own stderr (a crash's last words), for the report."""
    try:
        text = path.read_text(errors='replace').strip().splitlines()
    except OSError:
        return ''
    text = [line for line in text if 'running over TCP without encryption' not in line]
    return ('; kernel output: ' + ' | '.join(text[-lines:])) if text else ''


def _kernel_tree(km: KernelManager,
                 known: list[psutil.Process] | None = None) -> list[psutil.Process]:
    """The kernel and its descendants so far (remembered in case they lose their parent)."""
    import psutil

    found = {p.pid: p for p in known or []}
    pid = getattr(km.provisioner, 'pid', None) if km.provisioner is not None else None
    if pid:
        with contextlib.suppress(psutil.Error):
            kernel = psutil.Process(pid)
            found.setdefault(kernel.pid, kernel)
            for child in kernel.children(recursive=True):
                found.setdefault(child.pid, child)
    return list(found.values())


class _Watchdog:
    """Interrupts a cell that runs past its time, and kills a kernel that ignores that.

    A thread of its own sends the signals, so nbclient's bookkeeping stays intact: the
    interrupted cell ends with KeyboardInterrupt like Jupyter's stop button, and a killed
    kernel surfaces as nbclient's DeadKernelError.
    """

    def __init__(self, km: KernelManager, timeout: float, grace: float) -> None:
        self.pid: int | None = getattr(km.provisioner, 'pid', None)
        self.timeout = timeout
        self.grace = grace
        self.interrupted = False
        self.killed = False
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._watch, name='robot_lab-grade-watchdog',
                                        daemon=True)

    def _signal(self, signum: int) -> None:
        if self.pid is not None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signum)

    def _watch(self) -> None:
        if self._done.wait(self.timeout):
            return
        self.interrupted = True
        self._signal(signal.SIGINT)
        if self._done.wait(self.grace):
            return
        self.killed = True
        self._signal(signal.SIGKILL)

    def __enter__(self) -> _Watchdog:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._done.set()
        self._thread.join()
