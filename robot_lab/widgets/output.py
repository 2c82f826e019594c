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
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import IO, Any, ParamSpec, TypeVar

__all__ = ['WidgetLog', 'in_ci', 'is_headless', 'routed_to']

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
            sys.stdout = _ThreadRouter(sys.stdout)  # type: ignore[assignment]
        if not isinstance(sys.stderr, _ThreadRouter):
            sys.stderr = _ThreadRouter(sys.stderr)  # type: ignore[assignment]


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


class WidgetLog:
    """A bounded text log shown in a widget, safe to write from any thread.

    The widget is refreshed at most `refresh_hz` times a second, so a chatty callback
    costs the kernel one small message per interval, not one per line.
    """

    def __init__(self, max_lines: int = 200, height: str = '12em', refresh_hz: float = 10.0,
                 render: Callable[[list[str]], str] | None = None) -> None:
        self.lines: deque[str] = deque(maxlen=max_lines)
        self._partial = ''
        self._lock = threading.Lock()
        self._interval = 1.0 / refresh_hz
        self._last = 0.0
        self._timer: threading.Timer | None = None
        self._height = height
        self._render = render or self.render_plain
        self._widget: Any = None

    @property
    def widget(self) -> Any:
        """An ipywidgets.HTML showing the last lines (created on first use)."""
        if self._widget is None:
            import ipywidgets as widgets

            self._widget = widgets.HTML(layout=widgets.Layout(width='100%'))
            self._widget.value = self._render(list(self.lines))
        return self._widget

    def render_plain(self, lines: list[str]) -> str:
        empty = '<span style="color:#888">(nothing yet)</span>'
        body = html.escape('\n'.join(lines)) if lines else empty
        return (f'<pre style="max-height:{self._height};overflow-y:auto;margin:0;'
                f'font-size:12px;line-height:1.35">{body}</pre>')

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
            self._widget.value = self._render(lines)

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
