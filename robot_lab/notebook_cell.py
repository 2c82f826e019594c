"""A notebook cell and what its run started: a re-run replaces it, a failed run leaves nothing.

A student runs a cell, reads the ✗, edits and runs it again, many times, in one kernel.
Whatever a run of a cell started (a plot, a console, a node a check started) is owned by
that run: the next run of the same cell closes it first, and a run that ends in an error
closes it at once, so a re-run is judged on the current answer alone and never meets a
node left over from the last attempt.

A cell is named by JupyterLab's `cellId` (execute request metadata) when the frontend
sends one, else by its code (nbclient, nbval and nbgrader send none; a check cell's code
is locked). One run is one execute request.

An error a cell raises (a NameError, a wrong call into rclpy, a typo in a node class) shows
the student's own frames and one `Try:` line, not the kit's and the libraries' frames
(`show_their_errors`, from every notebook's set-up cell). Instructors see everything with
ROBOT_LAB_FULL_TRACEBACKS=1 (or the instructor's Lab, ROBOT_LAB_INSTRUCTOR=1).
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading
from types import TracebackType
from typing import Any, Protocol

from robot_lab.errors import RobotLabError

__all__ = ['Closable', 'cell_owns', 'current_cell', 'full_tracebacks', 'new_run',
           'outside_the_kit', 'show_their_error', 'show_their_errors', 'their_traceback',
           'try_line']


class Closable(Protocol):
    def close(self) -> None: ...


_CELL_RUNS: dict[str, tuple[str, list[Closable]]] = {}
_CELL_LOCK = threading.Lock()
_HOOKED: set[int] = set()


def outside_the_kit(filename: str) -> bool:
    """A frame of the student's code: not the kit's, Python's or an installed library's."""
    from pathlib import Path

    kit = str(Path(__file__).resolve().parent)
    libraries = {sys.prefix, sys.base_prefix, sys.exec_prefix}
    return not filename.startswith((kit, '<frozen', *libraries))


def their_traceback(err: BaseException) -> list[str]:
    """`err`'s traceback cut to the student's frames (and the error line); [] if none."""
    import traceback

    frames = [f for f in traceback.extract_tb(err.__traceback__) if outside_the_kit(f.filename)]
    if not frames:
        return []
    lines = [f'  File "{f.filename}", line {f.lineno}, in {f.name}'
             + (f'\n    {f.line.strip()}' if f.line else '') for f in frames]
    return [*lines, type(err).__name__ + (f': {err}' if str(err) else '')]


def _kernel_request() -> dict[str, Any] | None:
    try:
        from IPython import get_ipython
    except ImportError:
        return None
    kernel = getattr(get_ipython(), 'kernel', None)
    if kernel is None:
        return None
    parent: dict[str, Any] = kernel.get_parent() or {}
    return parent


def current_cell() -> tuple[str, str] | None:
    """(cell, id of this run) of the notebook cell executing now; None outside a kernel."""
    parent = _kernel_request()
    if not parent:
        return None
    run = (parent.get('header') or {}).get('msg_id')
    cell = (parent.get('metadata') or {}).get('cellId')
    if not cell:
        code = (parent.get('content') or {}).get('code')
        if code is None:
            return None
        cell = 'code:' + hashlib.sha1(str(code).encode()).hexdigest()
    return (str(cell), str(run)) if run else None


def _close_all(owned: list[Closable]) -> None:
    for thing in reversed(owned):  # the last started first: a console outlives its node
        try:
            thing.close()
        except Exception as err:  # one failure must not keep the rest running
            print(f'could not close {thing!r}: {err}', file=sys.stderr)


def new_run() -> None:
    """Close what earlier runs of the executing cell started (a check calls this first)."""
    where = current_cell()
    if where is None:
        return
    _hook_failures()
    cell, run = where
    with _CELL_LOCK:
        last_run, owned = _CELL_RUNS.get(cell, ('', []))
        if last_run == run:
            return
        _CELL_RUNS[cell] = (run, [])
    _close_all(owned)


def cell_owns(thing: Closable) -> None:
    """`thing` belongs to this run of the executing cell (closed on its re-run or error)."""
    where = current_cell()
    if where is None:
        return
    new_run()
    cell, run = where
    with _CELL_LOCK:
        _CELL_RUNS.setdefault(cell, (run, []))[1].append(thing)


def _after_cell(result: Any) -> None:
    """A run that raised keeps nothing it started (IPython's post_run_cell event)."""
    if getattr(result, 'error_in_exec', None) is None:
        return
    where = current_cell()
    if where is None:
        return
    cell, run = where
    with _CELL_LOCK:
        last_run, owned = _CELL_RUNS.get(cell, ('', []))
        if last_run != run or not owned:
            return
        _CELL_RUNS[cell] = (run, [])
    _close_all(owned)


def _hook_failures() -> None:
    from IPython import get_ipython

    shell = get_ipython()
    if shell is None or id(shell) in _HOOKED:
        return
    _HOOKED.add(id(shell))
    shell.events.register('post_run_cell', _after_cell)


# --- a cell's own errors: the student's frames and one line of advice --------------------

_FULL_SWITCHES = ('ROBOT_LAB_FULL_TRACEBACKS', 'ROBOT_LAB_INSTRUCTOR')
_BOLD, _RESET = '\x1b[1m', '\x1b[0m'


def full_tracebacks() -> bool:
    """The instructor's switch: every frame, as IPython shows them (read at each error)."""
    return any(os.environ.get(name, '').strip().lower() not in ('', '0', 'false', 'no')
               for name in _FULL_SWITCHES)


def _their_frames(tb: TracebackType | None) -> tuple[TracebackType | None, list[TracebackType]]:
    """`tb` rebuilt from the student's frames only, and every frame of the original."""
    frames: list[TracebackType] = []
    while tb is not None:
        frames.append(tb)
        tb = tb.tb_next
    kept: TracebackType | None = None
    for frame in reversed([f for f in frames if outside_the_kit(f.tb_frame.f_code.co_filename)]):
        kept = TracebackType(kept, frame.tb_frame, frame.tb_lasti, frame.tb_lineno)
    return kept, frames


def _close(name: str, candidates: list[str]) -> str:
    import difflib

    found = difflib.get_close_matches(name, [c for c in candidates if c != name], n=1)
    return f'did you mean `{found[0]}`? ' if found else ''


def _library(filename: str) -> str:
    """`rclpy/node.py` → `rclpy.node`: where a library frame is, as an import would name it."""
    from pathlib import Path

    parts = list(Path(filename).with_suffix('').parts)
    for top in ('site-packages', 'robot_lab'):
        if top in parts:
            at = len(parts) - 1 - parts[::-1].index(top)
            parts = parts[at + (top == 'site-packages'):]
            break
    return '.'.join(p for p in parts[-3:] if p != '__init__')


def try_line(err: BaseException, frames: list[TracebackType],
             names: dict[str, Any] | None = None) -> str:
    """How to fix `err` (raised through `frames`), in one line; '' when its own line says.

    `names` are the kernel's (to suggest what a misspelt name was meant to be).
    """
    import builtins

    mine = [i for i, f in enumerate(frames) if outside_the_kit(f.tb_frame.f_code.co_filename)]
    line = f'line {frames[mine[-1]].tb_lineno}' if mine else 'the line above'
    known = [*(names or {}), *dir(builtins)]
    if isinstance(err, RobotLabError):
        return '' if err.fix else 'fix what the line above names, then run the cell again'
    hint = getattr(err, 'try_hint', None)  # a library's own advice (tf2's exceptions)
    if isinstance(hint, str) and hint:
        return hint
    name = getattr(err, 'name', None)
    if isinstance(err, NameError) and isinstance(name, str):
        return (f'{_close(name, known)}`{name}` is not defined here: check its spelling, '
                'or run the cell that defines or imports it first')
    if isinstance(err, AttributeError) and isinstance(name, str):
        obj = getattr(err, 'obj', None)
        what = type(obj).__name__ if obj is not None else 'that object'
        return (f'{_close(name, dir(obj) if obj is not None else [])}a {what} has no '
                f'`{name}`: check the spelling at {line} (dir(x) lists what x has)')
    if isinstance(err, ModuleNotFoundError) and err.name:
        return (f'no module `{err.name}` here: check its spelling; for your own package, build '
                "it (colcon build) and run robot_lab.use_workspace(ws), the notebook's "
                '`source install/setup.bash`')
    if isinstance(err, ImportError) and err.name and err.name in sys.modules:
        wanted = str(err).split("'")[1] if str(err).count("'") >= 2 else ''
        return (f'{_close(wanted, dir(sys.modules[err.name]))}`{err.name}` has no '
                f'`{wanted}`: check the name and where it comes from')
    if 'must only be called once' in str(err):
        return ('the kit has started rclpy in this kernel already: leave out rclpy.init() '
                'and rclpy.shutdown() in notebook cells')
    inside = frames[mine[-1] + 1:] if mine else frames
    if inside:
        code = inside[0].tb_frame.f_code
        called = f'{_library(code.co_filename)}.{code.co_name}'
        return (f'the call at your {line} gives {called}() a value it refuses: compare each '
                f'argument with help({called.rsplit(".", 1)[-1] if "." in called else called})'
                ' or the ROS 2 docs, fix it, and run the cell again')
    return f'read your {line} (marked above): the last line says what Python found wrong there'


def show_their_error(shell: Any, etype: type[BaseException], value: BaseException,
                     tb: TracebackType | None) -> list[str]:
    """Show `value` the way a student can act on: their frames, the error, a `Try:` line."""
    if full_tracebacks() or hasattr(value, '_render_traceback_'):
        shell.showtraceback((etype, value, tb))  # CheckError renders itself
        return []
    kept, frames = _their_frames(tb)
    chained = (value.__cause__, value.__context__, value.__suppress_context__)
    value.__cause__, value.__context__ = None, None  # the kit's inner errors stay inside
    try:
        # tb_offset=0: IPython 8 (Python 3.10's) would drop the first of the student's frames
        # (the shell's own offset of 1 hides its exec frame, not in `kept`); 9 ignores it.
        shown: list[str] = shell.InteractiveTB.structured_traceback(etype, value, kept,
                                                                    tb_offset=0)
    finally:
        value.__cause__, value.__context__, value.__suppress_context__ = chained
    advice = try_line(value, frames, shell.user_ns)
    shown += [f'{_BOLD}Try:{_RESET} {advice}'] if advice else []
    shell._showtraceback(etype, value, shown)
    return shown


def show_their_errors() -> None:
    """In this kernel, a cell's error shows the student's frames only (`show_their_error`)."""
    try:
        from IPython import get_ipython
    except ImportError:
        return
    shell = get_ipython()
    if shell is None or getattr(shell, 'kernel', None) is None:
        return

    def handler(shell: Any, etype: type[BaseException], value: BaseException,
                tb: TracebackType | None, tb_offset: int | None = None) -> list[str]:
        return show_their_error(shell, etype, value, tb)

    shell.set_custom_exc((Exception,), handler)
