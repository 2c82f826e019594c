"""The supervisor's event handlers: which registered handler answers which event.

RegisterEventHandler puts an EventHandlerSpec into the plan; when the supervisor executes
it, it lands here. The supervisor reports each process start, output line, exit and the
shutdown; matching handlers resolve their actions then, and the supervisor runs them. A
handler that fails (a Python error in an `on_exit=lambda ...`) is reported as one line,
with its file and line, and the launch shuts down as launch does on an exception.
"""

from __future__ import annotations

from collections.abc import Callable

from robot_lab.errors import RobotLabError
from robot_lab.launch.events import (
    EventKind,
    ExecutionComplete,
    ProcessExited,
    ProcessIO,
    ProcessStarted,
)
from robot_lab.launch.plan import Action, EventHandlerSpec, ProcessSpec

__all__ = ['EventRouter']


class EventRouter:
    """Registered handlers, asked in registration order."""

    def __init__(self, execute: Callable[[list[Action]], None],
                 fail: Callable[[str], None],
                 defer: Callable[[Callable[[], None]], None]) -> None:
        self._execute = execute
        self._fail = fail
        self._defer = defer
        self.handlers: list[EventHandlerSpec] = []

    def register(self, handler: EventHandlerSpec) -> None:
        self.handlers.append(handler)

    def wants(self, kind: EventKind) -> bool:
        return any(h.event == kind for h in self.handlers)

    def emit(self, kind: EventKind, origin: object, make_event: Callable[[], object]) -> None:
        """Queue the event; the handlers of `kind` watching `origin` (None: any) answer it
        on the supervisor's next turn, as launch's event loop does — so a handler registered
        right after the action it watches still sees that action's first events."""
        if kind not in ('process_start', 'process_exit', 'execution_complete') and \
                not any(h.event == kind for h in self.handlers):
            return  # (a process's own handlers may be registered right after it starts)
        event = make_event()
        if kind == 'shutdown':  # its handlers' actions come before the processes are signalled
            self._dispatch(kind, origin, event)
        else:
            self._defer(lambda: self._dispatch(kind, origin, event))

    def _dispatch(self, kind: EventKind, origin: object, event: object) -> None:
        matching = [h for h in self.handlers if h.event == kind and
                    (origin is None or h.matches(origin))]
        for handler in matching:
            try:
                actions = handler.respond(event)
            except RobotLabError as err:
                self._fail(str(err))
                return
            except Exception as err:  # never let a handler take the supervisor down
                self._fail(f'{handler.description} raised {type(err).__name__}: {err}')
                return
            self._execute(actions)

    # --- the events of one process ------------------------------------------------------

    def started(self, spec: ProcessSpec, pid: int, env: dict[str, str]) -> None:
        self.emit('process_start', spec.origin, lambda: ProcessStarted(
            spec.origin, spec.label, spec.cmd, spec.cwd, env, pid))

    def output(self, spec: ProcessSpec, pid: int, stream: str, line: bytes) -> None:
        self.emit('process_io', spec.origin, lambda: ProcessIO(
            spec.origin, spec.label, spec.cmd, spec.cwd, spec.env, pid,
            text=line + b'\n', fd=1 if stream == 'stdout' else 2))

    def exited(self, spec: ProcessSpec, pid: int, returncode: int) -> None:
        self.emit('process_exit', spec.origin, lambda: ProcessExited(
            spec.origin, spec.label, spec.cmd, spec.cwd, spec.env, pid, returncode))
        self.emit('execution_complete', spec.origin, lambda: ExecutionComplete(spec.origin))
