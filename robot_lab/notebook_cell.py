"""A notebook cell and what its run started: a re-run replaces it, a failed run leaves nothing.

A student runs a cell, reads the ✗, edits and runs it again, many times, in one kernel.
Whatever a run of a cell started (a plot, a console, a node a check started) is owned by
that run: the next run of the same cell closes it first, and a run that ends in an error
closes it at once, so a re-run is judged on the current answer alone and never meets a
node left over from the last attempt.

A cell is named by JupyterLab's `cellId` (execute request metadata) when the frontend
sends one, else by its code (nbclient, nbval and nbgrader send none; a check cell's code
is locked). One run is one execute request.
"""

from __future__ import annotations

import hashlib
import sys
import threading
from typing import Any, Protocol

__all__ = ['Closable', 'cell_owns', 'current_cell', 'new_run', 'outside_the_kit', 'their_traceback']


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
