"""Runs a LaunchPlan: starts, watches, respawns and stops its processes like launch does.

One thread does everything (spawn, timers, output, signals to children): the thread that
calls `Supervisor.run()`. Children are started with `robot_lab.process.spawn`, whose
parent-death signal is tied to that thread, so run() must be called from a thread that
lives as long as the launch (the CLI's main thread, or the notebook's supervisor thread).
The launcher has no DDS participant of its own: it never imports rclpy, so the nodes it
starts find each other as fast as bare processes do. What it does for graph queries
(announcing its nodes, a graph daemon beside them) is robot_lab/graph/launch_companion.py:
the supervisor only reports which node runs where (graph_watch.py). A child's pipes are
child_output.py's, how one child starts and stops process_control.py's; this is the loop.
"""

from __future__ import annotations

import contextlib
import heapq
import itertools
import os
import selectors
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from robot_lab.env import apply_ros_defaults
from robot_lab.graph.launch_companion import DAEMON_CHECK, LaunchGraphCompanion
from robot_lab.launch.child_output import ChildOutput
from robot_lab.launch.event_router import EventRouter
from robot_lab.launch.events import Shutdown
from robot_lab.launch.fork_client import ForkedProcess, ForkServer, enabled, interpreter_of
from robot_lab.launch.graph_watch import GraphWatch
from robot_lab.launch.output import LaunchOutput
from robot_lab.launch.plan import (
    Action,
    EventHandlerSpec,
    LaunchPlan,
    LifecycleRequest,
    LogAction,
    ProcessSpec,
    ShutdownAction,
    TimerSpec,
)
from robot_lab.launch.process_control import exit_fd, kill_leftovers, start_child, stop_process
from robot_lab.launch.process_record import ProcessRecord, Scheduled, domain_of
from robot_lab.shared_memory import HEARING_CHECK, sweep_dead_segments

if TYPE_CHECKING:
    from robot_lab.graph.daemon import Listener
    from robot_lab.graph.expected import LaunchAnnouncement
    from robot_lab.launch.lifecycle_bridge import LifecycleBridge

__all__ = ['Supervisor']

_LEVELS = {'DEBUG', 'INFO', 'WARNING', 'ERROR', 'CRITICAL'}


class Supervisor:
    """Executes one LaunchPlan; `run()` blocks until every process has ended."""

    def __init__(self, plan: LaunchPlan, output: LaunchOutput, *,
                 noninteractive: bool = True, graph_daemon: bool = False,
                 graph_listener: Listener | None = None,
                 announcement: LaunchAnnouncement | None = None,
                 fork_server: ForkServer | None = None) -> None:
        self.plan = plan
        self.output = output
        self.noninteractive = noninteractive
        self.graph_daemon = graph_daemon
        self._graph = LaunchGraphCompanion(
            daemon=graph_daemon, listener=graph_listener, announcement=announcement,
            warn=lambda message: self.output.launcher('WARNING', 'launch', message))
        self.records: list[ProcessRecord] = [ProcessRecord(spec) for spec in plan.processes()]
        self._by_spec = {id(r.spec): r for r in self.records}
        self._watch = GraphWatch(self.records, self._graph, output)
        self._labels = len(self.records)  # processes an event handler starts count on
        self.events = EventRouter(self._execute, self._handler_failed, self._request)
        self._lifecycle: LifecycleBridge | None = None  # made for the first lifecycle node
        self.started = threading.Event()  # the plan's first actions have been executed
        self.finished = threading.Event()
        self.is_shutdown = False
        self.returncode = 0
        self._schedule: list[Scheduled] = []
        self._seq = itertools.count()
        self._selector = selectors.DefaultSelector()
        self._streams = ChildOutput(self._selector, output, self.events)
        self._requests: list[Callable[[], None]] = []
        # Re-entrant: Ctrl-C's handler takes it in the main thread, which may hold it already
        # (draining requests) or be running that handler for an earlier signal. `timeout -s
        # INT` signals the launcher twice (it and its group); with a plain Lock the second
        # handler waited on the first forever (CI: a launcher hung with its nodes reaped
        # by nobody, after its kernel was gone).
        self._requests_lock = threading.RLock()
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self._sigint_seen = False
        self._closed = False
        self._forks: ForkServer | None = None  # unless ROBOT_LAB_FORK_SERVER=0: see fork_client
        self._early_forks = fork_server  # started before the plan existed (start_early)

    # --- requests from other threads (Ctrl-C handler, notebook handle) -------------------

    def _request(self, fn: Callable[[], None]) -> None:
        with self._requests_lock:
            if self._closed:
                return  # the launch has ended; nothing left to stop
            self._requests.append(fn)
            # A full pipe means the loop is awake anyway.
            with contextlib.suppress(OSError):
                os.write(self._wake_w, b'x')

    def interrupt(self) -> None:
        """What Ctrl-C does: the first shuts down, later ones are noted and ignored."""

        def handle() -> None:
            message = 'user interrupted with ctrl-c (SIGINT)'
            if self._sigint_seen:
                self.output.launcher('WARNING', 'launch', f'{message} again, ignoring...')
                return
            self._sigint_seen = True
            self.output.launcher('WARNING', 'launch', message)
            self._shutdown(due_to_sigint=True)

        self._request(handle)

    def terminate(self) -> None:
        """SIGTERM to the launcher: stop the children the same orderly way, then exit."""

        def handle() -> None:
            self.output.launcher('WARNING', 'launch', 'received SIGTERM: shutting down')
            self._shutdown(due_to_sigint=False)

        self._request(handle)

    def shutdown(self, reason: str = '') -> None:
        """Stop everything (SIGINT to each child, then SIGTERM, then SIGKILL)."""
        self._request(lambda: self._shutdown(due_to_sigint=False, reason=reason))

    # --- the loop -----------------------------------------------------------------------

    def run(self) -> int:
        """Execute the plan until all processes are gone; returns the launch's exit code."""
        self._selector.register(self._wake_r, selectors.EVENT_READ, ('wake', None, ''))
        try:
            self._announce_planned()
            self._start_fork_server()
            self._execute(self.plan.actions)
            self.started.set()
            if self.graph_daemon:
                self._watch.start_daemons()
                self._every(DAEMON_CHECK, self._watch.check_daemons)
            self._every(HEARING_CHECK, self._watch.check_hearing)
            while True:
                self._drain_requests()
                self._run_due()
                if self._idle():
                    if self.is_shutdown and not self._requests:
                        break
                    self._shutdown(due_to_sigint=False, reason='idle')  # OnShutdown handlers
                    continue
                self._wait(self._next_timeout())
        finally:
            self.started.set()
            kill_leftovers(self.records)
            sweep_dead_segments()  # what killed nodes (this launch's or others') left in RAM
            if self._forks is not None:
                self._forks.close()
            self._graph.close()
            if self._lifecycle is not None:
                self._lifecycle.close()
            self._selector.close()
            with self._requests_lock:
                self._closed = True
                for fd in (self._wake_r, self._wake_w):
                    os.close(fd)
            self.finished.set()
        return self.returncode

    def _idle(self) -> bool:
        if any(r.state == 'running' for r in self.records):
            return False
        return not any(not s.cancelled and s.keeps_alive for s in self._schedule)

    def _next_timeout(self) -> float:
        live = [s for s in self._schedule if not s.cancelled]
        # Without pidfds, exits are noticed by polling; keep that latency short. A forked
        # node's exit comes on the fork server's socket, while the server lives.
        evented = self._forks is not None and self._forks.error is None
        cap = 0.5 if all(r.pidfd is not None or (evented and isinstance(r.popen, ForkedProcess))
                         for r in self.records if r.state == 'running') else 0.1
        if not live:
            return cap
        return max(0.0, min(cap, min(s.due for s in live) - time.monotonic()))

    def _wait(self, timeout: float) -> None:
        for key, _ in self._selector.select(timeout):
            kind, record, stream = key.data
            if kind == 'wake':
                try:
                    while os.read(self._wake_r, 4096):
                        pass
                except BlockingIOError:
                    pass
            elif kind == 'pipe':
                self._streams.read(record, stream, key.fd)
            elif kind == 'exit':
                self._reap(record)
            elif kind == 'forks':
                self._forks_message()
        for record in self.records:
            if record.state == 'running' and record.popen is not None \
                    and record.popen.poll() is not None:
                self._reap(record)

    def _forks_message(self) -> None:
        """The fork server has sent exit statuses (taken here, reaped by `_wait`), or
        ended: its socket is then read no more (its nodes died with it, see ForkedProcess)."""
        assert self._forks is not None
        self._forks.pump(0.0)
        if self._forks.error is not None:
            with contextlib.suppress(KeyError, ValueError):
                self._selector.unregister(self._forks.fileno())

    def _drain_requests(self) -> None:
        with self._requests_lock:
            requests, self._requests = self._requests, []
        for fn in requests:
            fn()

    def _at(self, delay: float, callback: Callable[[], None], *,
            keeps_alive: bool = True) -> Scheduled:
        item = Scheduled(time.monotonic() + delay, next(self._seq), callback, keeps_alive)
        heapq.heappush(self._schedule, item)
        return item

    def _later(self, delay: float, callback: Callable[[], None]) -> None:
        """A callback that does not keep the launch alive (signal escalations)."""
        self._at(delay, callback, keeps_alive=False)

    def _every(self, period: float, check: Callable[[], None]) -> None:
        """`check` every `period` seconds until shutdown; never keeps the launch alive."""

        def tick() -> None:
            if self.is_shutdown:
                return
            check()
            self._every(period, check)

        self._later(period, tick)

    def _run_due(self) -> None:
        while self._schedule and self._schedule[0].due <= time.monotonic():
            item = heapq.heappop(self._schedule)
            if not item.cancelled:
                item.callback()
        self._schedule = [s for s in self._schedule if not s.cancelled]
        heapq.heapify(self._schedule)

    # --- actions ------------------------------------------------------------------------

    def _execute(self, actions: list[Action]) -> None:
        for action in actions:
            if isinstance(action, ProcessSpec):
                record = self._by_spec.get(id(action)) or self._adopt(action)
                self._start(record)
            elif isinstance(action, EventHandlerSpec):
                self.events.register(action)
            elif isinstance(action, LifecycleRequest):
                self._lifecycle_bridge().request_matching(action)
            elif isinstance(action, LogAction):
                level = action.level.upper()
                self.output.launcher(level if level in _LEVELS else 'INFO', 'launch.user',
                                     action.message)
            elif isinstance(action, TimerSpec) and not self.is_shutdown:
                self._at(max(0.0, action.period), self._timer_callback(action.actions))
            elif isinstance(action, ShutdownAction):
                self._shutdown(due_to_sigint=False, reason=action.reason)

    def _adopt(self, spec: ProcessSpec) -> ProcessRecord:
        """A process an event handler asked for: numbered after those of the plan."""
        self._labels += 1
        spec.label = f'{spec.label}-{self._labels}'
        record = ProcessRecord(spec)
        self.records.append(record)
        self._by_spec[id(spec)] = record
        return record

    def _handler_failed(self, message: str) -> None:
        self.output.launcher('ERROR', 'launch', message)
        self.returncode = 1
        self._shutdown(due_to_sigint=False, reason='an event handler failed')

    def _lifecycle_bridge(self) -> LifecycleBridge:
        if self._lifecycle is None:  # rclpy is imported only for a plan with lifecycle nodes
            from robot_lab.launch.lifecycle_bridge import LifecycleBridge

            self._lifecycle = LifecycleBridge(
                self.records, self.events, self._request, self._environment,
                lambda level, message: self.output.launcher(level, 'launch', message))
        return self._lifecycle

    def _timer_callback(self, actions: list[Action]) -> Callable[[], None]:
        return lambda: self._execute(actions)

    def _environment(self, spec: ProcessSpec) -> dict[str, str]:
        # The frontends resolve the whole environment (set_env/unset_env applied); a
        # hand-built spec may leave it empty, meaning "this process's environment".
        env = dict(spec.env) if spec.env else dict(os.environ)
        apply_ros_defaults(env)
        return env

    def _start_fork_server(self) -> None:
        """Before the first spawn, so its imports run while the launcher gets going; or
        the one started before the plan existed, if it suits the first forkable node."""
        early, self._early_forks = self._early_forks, None
        for spec in self.plan.processes() if enabled() else []:
            if interpreter_of(spec) is not None:
                env = self._environment(spec)
                if early is not None and early.accepts(env):
                    self._forks, early, when = early, None, 'before the launch file was read'
                else:
                    with contextlib.suppress(OSError):  # no server: every node is exec'd
                        self._forks, when = ForkServer(env), 'for the first Python node'
                if self._forks is not None:
                    self.output.launcher('DEBUG', 'launch',
                                         f'fork server [pid {self._forks.pid}] started {when}')
                    self._selector.register(self._forks.fileno(), selectors.EVENT_READ,
                                            ('forks', None, ''))
                break
        if early is not None:
            early.discard()

    def _start(self, record: ProcessRecord) -> None:
        if self.is_shutdown:
            return
        spec = record.spec
        self.output.launcher(
            'DEBUG', record.label,
            f"process details: cmd='{' '.join(p for p in spec.cmd if p.strip())}', "
            f"cwd='{spec.cwd}', custom_env?={'True' if spec.env else 'False'}")
        env = self._environment(spec)
        interpreter = interpreter_of(spec) if self._forks is not None else None
        try:
            popen = start_child(spec, env, self._forks, interpreter)
        except OSError as exc:
            record.state, record.returncode = 'died', None
            self.output.launcher('ERROR', record.label,
                                 f'exception occurred while executing process: {exc}')
            return
        record.popen, record.pid = popen, popen.pid
        record.state, record.returncode, record.stopping = 'running', None, False
        if spec.node_name:
            record.graph = self._graph.graph_of(env)
        record.generation += 1
        self._streams.watch(record, popen)
        record.pidfd = exit_fd(popen)
        if record.pidfd is not None:
            self._selector.register(record.pidfd, selectors.EVENT_READ, ('exit', record, ''))
        self.output.launcher('INFO', record.label, f'process started with pid [{popen.pid}]')
        self.events.started(spec, popen.pid, env)
        if spec.lifecycle and spec.node_name:
            self._lifecycle_bridge().watch(spec.node_name, domain_of(env),
                                           spec.lifecycle == 'autostart')
        self._announce()
        if self.graph_daemon and self.started.is_set():
            self._watch.start_daemons()  # a node started by a timer, maybe in a new graph

    # --- exits, respawn, shutdown -------------------------------------------------------

    def _reap(self, record: ProcessRecord) -> None:
        popen = record.popen
        if popen is None or record.state != 'running':
            return
        code = popen.wait()
        if record.pidfd is not None:
            with contextlib.suppress(KeyError, ValueError):
                self._selector.unregister(record.pidfd)
            os.close(record.pidfd)
            record.pidfd = None
        self._streams.drain(record)
        record.returncode = code
        cmd = ' '.join(part for part in record.spec.cmd if part.strip())
        spec = record.spec
        ending = self.is_shutdown or record.stopping
        required = not ending and spec.on_exit == 'shutdown'
        respawn = not ending and not required and spec.respawn and (
            spec.respawn_max_retries < 0 or record.retries < spec.respawn_max_retries)
        # the state is final before the line is out: a reader waiting on the line sees it
        record.state = 'respawning' if respawn else 'finished' if code == 0 else 'died'
        self._announce()  # after the state: the node is no longer announced as up
        if code == 0:
            self.output.launcher('INFO', record.label,
                                 f'process has finished cleanly [pid {popen.pid}]')
        else:
            self.output.launcher(
                'ERROR', record.label,
                f"process has died [pid {popen.pid}, exit code {code}, cmd '{cmd}'].",
            )
        self.events.exited(spec, popen.pid, code)
        if required:
            self.output.launcher(
                'INFO', 'launch',
                f'process[{record.label}] was required: shutting down launched system',
            )
            self._shutdown(due_to_sigint=False, reason=f'{record.label} exited')
        elif respawn:
            record.retries += 1
            self._at(max(0.0, spec.respawn_delay), lambda: self._respawn(record))

    def _respawn(self, record: ProcessRecord) -> None:
        if record.state == 'respawning' and not self.is_shutdown:
            self._start(record)

    def _shutdown(self, *, due_to_sigint: bool, reason: str = '') -> None:
        if self.is_shutdown:
            return
        self.is_shutdown = True
        if reason:
            self.output.launcher('DEBUG', 'launch', f'shutting down: {reason}')
        self.events.emit('shutdown', None, lambda: Shutdown(
            'ctrl-c (SIGINT)' if due_to_sigint else reason or 'reason not given', due_to_sigint))
        self._graph.stop_daemons()  # it exits while the nodes do
        for item in self._schedule:
            if item.keeps_alive:
                item.cancelled = True  # timers and pending respawns never start now
        for record in self.records:
            if record.state == 'respawning':
                record.state = 'died' if record.returncode else 'finished'
        send_sigint = not due_to_sigint or self.noninteractive
        # launch signals the newest process first; so do we.
        for record in reversed(self.records):
            if record.state == 'running':
                stop_process(record, self.output, send_sigint=send_sigint, later=self._later)

    # --- graph companions: expected nodes (the graph daemon, hearing: graph_watch) -------

    def _announce_planned(self) -> None:
        """Before the first spawn: the nodes about to start are expected already, so a
        `node list` that reaches a warm daemon first waits for them."""
        for action in self.plan.actions:
            if isinstance(action, ProcessSpec) and action.node_name:
                self._by_spec[id(action)].graph = self._graph.graph_of(self._environment(action))
        self._announce()

    def _announce(self) -> None:
        """The nodes up or about to start, after every change of a record's state."""
        self._watch.announce(shutting_down=self.is_shutdown)
