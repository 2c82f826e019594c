"""Where background output goes: to the widget that owns the thread, not the next cell.

ipykernel sends a print from a thread it did not start to whichever cell is executing
now (the thread has no parent header of its own). ROS callbacks run on the session's
executor threads, so a plot's or console's message would land in an unrelated cell.
Widgets therefore write into a `WidgetLog`, and run their callbacks through
`WidgetLog.guard`, which routes `print` and tracebacks of that thread into the log.
"""

from __future__ import annotations

import html
import os
import sys
import threading
import time
import traceback
import weakref
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import IO, TYPE_CHECKING, Any, ParamSpec, TypeVar

from robot_lab.notebook_cell import Closable, cell_owns, current_cell

if TYPE_CHECKING:
    from ipywidgets import Widget

__all__ = ['WidgetLog', 'close_widgets', 'current_cell', 'in_ci', 'is_headless', 'owned_by_cell',
           'routed_to', 'scroll_box']

P = ParamSpec('P')
R = TypeVar('R')

_TRUE = {'1', 'true', 'yes', 'on'}
_FALSE = {'0', 'false', 'no', 'off'}


def in_ci() -> bool:
    """True under CI (env CI=true): waits are shorter there."""
    return os.environ.get('CI', '').strip().lower() in _TRUE


def is_headless() -> bool:
    """True when no one is watching: nbval/nbconvert runs, CI, plain scripts.

    ROBOT_LAB_HEADLESS=1/0 decides when set; otherwise CI means headless, and so does
    running outside an IPython kernel (there is no frontend to draw a live widget).
    """
    flag = os.environ.get('ROBOT_LAB_HEADLESS', '').strip().lower()
    if flag in _TRUE:
        return True
    if flag in _FALSE:
        return False
    if in_ci():
        return True
    try:
        from IPython import get_ipython
    except ImportError:
        return True
    shell = get_ipython()
    return shell is None or not hasattr(shell, 'kernel')


_OPEN: weakref.WeakSet[Closable] = weakref.WeakSet()


def close_widgets() -> int:
    """Close every live widget this kernel made (plots, sliders, consoles, views).

    For a lesson's stop cell: unlike `live.close()`, it cannot fail on a name the student
    never (re)created, so the `shutdown()` after it always runs. Returns how many closed.
    """
    widgets = list(_OPEN)
    _OPEN.clear()
    for widget in widgets:
        try:
            widget.close()
        except Exception as err:  # one widget's failure must not keep the rest open
            print(f'could not close {widget!r}: {err}', file=sys.stderr)
    return len(widgets)


def owned_by_cell(widget: Closable) -> None:
    """Re-running a cell replaces what it made before: its previous run's widgets are closed.

    Otherwise each re-run of `live = robot_lab.plot(...)` would leave the old plot drawing
    20 frames a second, and subscribed, for the rest of the kernel's life (its view is gone
    from the page, so nobody could press a button to stop it). A cell that fails closes
    what it made (robot_lab.notebook_cell).
    """
    _OPEN.add(widget)
    cell_owns(widget)


class _ThreadRouter:
    """A stand-in for sys.stdout/sys.stderr that sends a routed thread's writes elsewhere."""

    def __init__(self, original: IO[str]) -> None:
        self.original = original

    def write(self, text: str) -> int:
        sink = _current_sink()
        if sink is None:
            return self.original.write(text)
        sink.write(text)
        return len(text)

    def flush(self) -> None:
        if _current_sink() is None:
            self.original.flush()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.original, name)


_ROUTES = threading.local()
_INSTALL_LOCK = threading.Lock()


def _current_sink() -> WidgetLog | None:
    stack: list[WidgetLog] | None = getattr(_ROUTES, 'stack', None)
    return stack[-1] if stack else None


def _install_router() -> None:
    """Wrap sys.stdout/sys.stderr once; unrouted threads write exactly as before."""
    with _INSTALL_LOCK:
        if not isinstance(sys.stdout, _ThreadRouter):
            sys.stdout = _ThreadRouter(sys.stdout)
        if not isinstance(sys.stderr, _ThreadRouter):
            sys.stderr = _ThreadRouter(sys.stderr)


@contextmanager
def routed_to(sink: WidgetLog) -> Iterator[WidgetLog]:
    """Inside this block, this thread's print() and tracebacks go to `sink`."""
    _install_router()
    stack: list[WidgetLog] = getattr(_ROUTES, 'stack', None) or []
    _ROUTES.stack = stack
    stack.append(sink)
    try:
        yield sink
    finally:
        stack.pop()


def scroll_box(body: str, height: str) -> str:
    """`body` in a box of at most `height` that shows its end, like a terminal.

    An HTML widget runs no script, so it cannot scroll itself; a column-reversed flex box
    starts scrolled to the bottom, so each refresh shows the newest lines, not the oldest.
    """
    # flex:none: a shrinkable child would be squeezed to the box and scroll on its own.
    return (f'<div style="max-height:{height};overflow-y:auto;display:flex;'
            f'flex-direction:column-reverse"><div style="flex:none">{body}</div></div>')


class WidgetLog:
    """A bounded text log shown in a widget, safe to write from any thread.

    The widget is refreshed at most `refresh_hz` times a second, so a chatty callback
    costs the kernel one small message per interval, not one per line. With `hide_empty`
    an empty log takes no room (a plot or sliders with nothing to report show no box).
    """

    def __init__(self, max_lines: int = 200, height: str = '12em', refresh_hz: float = 10.0,
                 render: Callable[[list[str]], str] | None = None,
                 hide_empty: bool = True) -> None:
        self.lines: deque[str] = deque(maxlen=max_lines)
        self._partial = ''
        self._lock = threading.Lock()
        self._interval = 1.0 / refresh_hz
        self._last = 0.0
        self._timer: threading.Timer | None = None
        self._height = height
        self._render = render or self.render_plain
        self._hide_empty = hide_empty
        self._widget: Widget | None = None

    @property
    def widget(self) -> Widget:
        """An ipywidgets.HTML showing the last lines (created on first use)."""
        if self._widget is None:
            import ipywidgets as widgets

            self._widget = widgets.HTML(layout=widgets.Layout(width='100%'))
            self._show(list(self.lines))
        return self._widget

    def _show(self, lines: list[str]) -> None:
        if self._widget is None:
            return
        self._widget.value = self._render(lines)
        self._widget.layout.display = 'none' if self._hide_empty and not lines else None

    def render_plain(self, lines: list[str]) -> str:
        empty = '<span style="color:#888">(nothing yet)</span>'
        body = html.escape('\n'.join(lines)) if lines else empty
        return scroll_box(f'<pre style="margin:0;font-size:12px;line-height:1.35">{body}</pre>',
                          self._height)

    def write(self, text: str) -> None:
        with self._lock:
            chunks = (self._partial + text).split('\n')
            self._partial = chunks.pop()
            self.lines.extend(chunks)
        self._schedule()

    def writeline(self, line: str) -> None:
        self.write(line.rstrip('\n') + '\n')

    def clear(self) -> None:
        with self._lock:
            self.lines.clear()
            self._partial = ''
        self.refresh()

    @property
    def text(self) -> str:
        with self._lock:
            return '\n'.join([*self.lines, self._partial] if self._partial else self.lines)

    def _schedule(self) -> None:
        if self._widget is None:
            return  # nobody shows it yet; `widget` renders everything when asked
        now = time.monotonic()
        with self._lock:
            if self._timer is not None:
                return
            wait = self._interval - (now - self._last)
            if wait > 0:
                self._timer = threading.Timer(wait, self.refresh)
                self._timer.daemon = True
                self._timer.start()
                return
        self.refresh()

    def refresh(self) -> None:
        """Push the current lines to the widget now."""
        with self._lock:
            self._timer = None
            self._last = time.monotonic()
            lines = list(self.lines)
        if self._widget is not None:
            self._show(lines)

    def guard(self, fn: Callable[P, R]) -> Callable[P, R | None]:
        """Wrap a callback: its prints and its exception go to this log, not a cell."""

        def _guarded(*args: P.args, **kwargs: P.kwargs) -> R | None:
            with routed_to(self):
                try:
                    return fn(*args, **kwargs)
                except Exception:  # a callback must not kill the executor
                    self.write(traceback.format_exc())
                    return None

        return _guarded
