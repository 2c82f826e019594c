"""A warm graph for one-shot commands: robot_lab's counterpart of the ros2 daemon.

A fresh `robot-lab node list` must start Python and rclpy and then wait for DDS discovery
before it can answer (≈ 1.7 s). ros2cli avoids that with a daemon: a long-lived process
whose participant already knows the graph, asked over a local socket. robot_lab does the
same. `robot-lab launch` starts one beside its nodes (it dies with the launcher, even after
`kill -9`), `robot-lab daemon start` starts one that exits after an idle timeout, and the
CLI's graph verbs ask it first and fall back to their own session when there is none.

One daemon per graph (user, ROS_DOMAIN_ID, discovery settings): its Unix socket lives in
`graph_dir()`, a per-user 0700 directory, and a lock file keeps it single. This module is
the daemon process (run as `python -m robot_lab.graph.daemon`); the side that binds its
socket, starts, asks and stops it is daemon_client.py, which imports neither rclpy nor the
graph modules, so asking costs a few milliseconds. Its names are re-exported here.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import faulthandler
import functools
import json
import os
import signal
import socket
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable
from typing import Any

from robot_lab.errors import RobotLabError
from robot_lab.graph.daemon_client import (
    _FLAG,
    AUTOSTART_VARIABLE,
    IDLE_TIMEOUT,
    NO_DAEMON_VARIABLE,
    OWNER_VARIABLE,
    QUERY_TIMEOUT,
    Listener,
    disabled,
    is_running,
    query,
    socket_path,
    start,
    start_for_later,
    stop,
    wait_until_running,
)
from robot_lab.graph.expected import graph_dir
from robot_lab.graph.stale_names import StaleNames
from robot_lab.linux.procfs import process_running
from robot_lab.shared_memory import HEARING_CHECK, lost_ports

__all__ = [
    'AUTOSTART_VARIABLE',
    'IDLE_TIMEOUT',
    'NO_DAEMON_VARIABLE',
    'OWNER_VARIABLE',
    'QUERY_TIMEOUT',
    'Listener',
    'disabled',
    'is_running',
    'query',
    'serve',
    'socket_path',
    'start',
    'start_for_later',
    'stop',
    'wait_until_running',
]

EXIT_WITHIN = 20.0  # s for the daemon's own exit, before its watchdog ends it (_main)


class _Server:
    """Answers graph queries from a session that stays warm between them."""

    def __init__(self, idle_timeout: float, owner: int | None = None) -> None:
        self.idle_timeout = idle_timeout
        self.owner = owner
        self.last_request = time.monotonic()
        self.stopping = threading.Event()
        self.session: Any = None
        self.stale = StaleNames()
        # (node name, pid) the launchers of this graph announced -> when last seen.
        self.announced: dict[tuple[str, int], float] = {}
        self.graph = graph_dir()
        # Connections being answered. At exit they are cut before the session closes: a
        # request in flight then reads a destroyed node (s17's CI printed `graph daemon:
        # InvalidHandle` for `topic info`), where a cut connection makes the command ask
        # the graph itself.
        self._in_flight: set[socket.socket] = set()
        self._in_flight_lock = threading.Lock()
        self.answered: dict[str, int] = {}  # op -> requests taken, errors too (`ping`)

    def handlers(self) -> dict[str, Callable[[dict[str, Any]], Any]]:
        from robot_lab.graph import actions, nodes, services, topics
        from robot_lab.graph import parameters as params

        def hidden(request: dict[str, Any]) -> bool:
            return bool(request.get('include_hidden', False))

        def name(request: dict[str, Any]) -> str:
            return str(request.get('name', ''))

        sess = self.session
        return {
            # ros2cli's daemon answers the info verbs too (any graph query); a warm graph
            # has every endpoint where a fresh participant may not have them yet.
            'action_list': lambda r: actions.action_list(session=sess),
            'node_info': lambda r: dataclasses.asdict(
                nodes.node_info(name(r), include_hidden=hidden(r), session=sess)),
            'topic_info': lambda r: dataclasses.asdict(topics.topic_info(name(r), session=sess)),
            'service_info': lambda r: dataclasses.asdict(
                services.service_info(name(r), session=sess)),
            'action_info': lambda r: dataclasses.asdict(actions.action_info(name(r),
                                                                            session=sess)),
            'ping': lambda r: {'pid': os.getpid(),
                               'age': time.monotonic() - self.session.created,
                               'in_flight': len(self._in_flight),
                               'answered': dict(self.answered)},
            'node_list': lambda r: self.node_list(hidden(r)),
            'topic_list': lambda r: topics.topic_list(hidden(r), session=self.session),
            'service_list': lambda r: services.service_list_typed(hidden(r),
                                                                  session=self.session),
            'stop': lambda r: self.stopping.set(),
            # Beyond ros2cli, whose param verbs each start a participant and wait to
            # discover the node's services (0.45-0.65 s a command on a quiet host, where
            # the daemon's warm clients answer in 0.15 s): the param verbs.
            **{op: functools.partial(params.answer, op, session=sess, listed=self.node_list)
               for op in params.PARAM_OPS},
        }

    def _live(self) -> tuple[dict[str, int], dict[str, int]]:
        """Per name: instances that are alive, and instances whose process has ended.

        The launchers' files (expected.py) say which process runs which node; the daemon
        remembers them, so a node whose process has ended (killed, crashed, its launcher
        killed with -9) leaves the list at once, not when its DDS lease runs out.
        """
        from robot_lab.graph.host_sockets import guid_pid_bits
        from robot_lab.graph.nodes import node_instances

        # Instances are told apart by pid bits only: one of a live announced process that
        # shares them with an ended one (pid_max > 65536) is not counted as ended.
        ended: set[tuple[str, int]] = set()
        running = Counter[tuple[str, int]]()
        for name, pid in self.announced:
            if process_running(pid):
                running[name, guid_pid_bits(pid)] += 1
            else:
                ended.add((name, guid_pid_bits(pid)))
        live: dict[str, int] = {}
        gone: dict[str, int] = {}
        for name, pids in node_instances(self.session).items():
            dead = sum(max(0, pids.count(bits) - running[name, bits])
                       for bits in {p for p in pids if p is not None and (name, p) in ended})
            live[name], gone[name] = len(pids) - dead, dead
        return live, gone

    def node_list(self, include_hidden: bool) -> list[str]:
        """`node list` from the warm graph, settled on what `current_nodes` keeps.

        The launches' announced nodes must be seen among the nodes kept, not merely among
        the names rmw lists: right after a kernel was killed with -9, its nodes' stale
        names would otherwise pass for the next launch's nodes not yet discovered, and the
        list would come back with the first node only.
        """
        from robot_lab.graph.discovery import full_node_names, settled
        from robot_lab.graph.expected import expected_nodes

        def probe() -> list[str]:
            return self.current_nodes(full_node_names(self.session, include_hidden))

        def ready() -> bool | None:
            expected = expected_nodes(self.graph)
            if expected is None:
                return False  # a launch is starting: its nodes are coming
            if not expected:
                return None
            return expected <= set(self.current_nodes(
                full_node_names(self.session, include_hidden=True)))

        return settled(self.session, probe, ready=ready, ready_settle=0.0)

    def current_nodes(self, listed: list[str]) -> list[str]:
        from robot_lab.graph.expected import expected_nodes

        live, gone = self._live()
        kept: list[str] = []
        for name in listed:
            if gone.get(name, 0) > 0:
                gone[name] -= 1
                continue
            kept.append(name)
        kept = self.stale.filter(kept, live)
        # A name a running launcher vouches for (its process is alive) is no ghost: the
        # guesses above must not hide it while rmw lists it (CI once saw a fresh launch
        # listed as /controller alone beside a killed kernel's ghosts).
        shown = set(kept)
        vouched = (expected_nodes(self.graph) or set()) - shown
        return sorted(kept + [name for name in dict.fromkeys(listed) if name in vouched])

    def audit(self) -> None:
        """Between requests (every half second): remember the launchers' nodes, watch the
        graph for stale names."""
        from robot_lab.graph.discovery import full_node_names
        from robot_lab.graph.expected import announced_nodes

        now = time.monotonic()
        for pair in announced_nodes(self.graph):
            self.announced[pair] = now
        for pair, seen in list(self.announced.items()):
            if now - seen > 60.0:  # ended long ago: its DDS lease has run out too
                del self.announced[pair]
        live, _gone = self._live()
        self.stale.audit(full_node_names(self.session, include_hidden=True), live)

    def handle(self, conn: socket.socket) -> None:
        try:
            self._answer(conn)
        finally:
            with self._in_flight_lock:
                self._in_flight.discard(conn)
            conn.close()

    def _answer(self, conn: socket.socket) -> None:
        try:
            conn.settimeout(5.0)
            line = conn.makefile('rb').readline()
            if not line.strip():
                return  # a probe (`is_running`): not a request, keeps nobody alive
            request = json.loads(line)
            self.last_request = time.monotonic()
            handler = self.handlers().get(str(request.get('op')))
            if handler is None:
                # `unknown`: a client newer than this daemon asks the graph itself
                reply: dict[str, Any] = {'error': f"unknown request {request.get('op')!r}",
                                         'unknown': True}
            else:
                with self._in_flight_lock:
                    op = str(request['op'])
                    self.answered[op] = self.answered.get(op, 0) + 1
                reply = {'result': handler(request)}
        except RobotLabError as err:
            reply = {'error': err.message, 'fix': err.fix}
        except Exception as exc:  # a bad request must not take the daemon down
            reply = {'error': f'graph daemon: {type(exc).__name__}: {exc}'}
        with contextlib.suppress(OSError):
            conn.sendall(json.dumps(reply).encode())

    def run(self, listener: Listener) -> int:
        listener.socket.settimeout(0.5)
        # The launcher's shutdown (SIGTERM) and a terminal's Ctrl-C (SIGINT, sent to the
        # whole foreground group) end the daemon the orderly way: socket removed.
        for sig in (signal.SIGTERM, signal.SIGINT):
            signal.signal(sig, lambda _s, _f: self.stopping.set())
        try:
            from robot_lab.rclpy_session import session

            self.session = session()
            # Idle from when it can answer: a slow start-up (a loaded machine) must not
            # count, or a short --idle-timeout ends the daemon before its first request.
            self.last_request = time.monotonic()
            heard_at = time.monotonic()
            while not self.stopping.is_set():
                if time.monotonic() - self.last_request > self.idle_timeout:
                    break
                if self.owner is not None and not process_running(self.owner):
                    break
                if time.monotonic() - heard_at >= HEARING_CHECK:
                    heard_at = time.monotonic()
                    if lost := lost_ports():
                        # A deaf daemon would list a stale graph until its idle timeout;
                        # without it, the next command answers from its own session and
                        # starts a daemon that hears everyone (ask_daemon).
                        print(f'robot-lab daemon: Fast DDS took over shared-memory port(s) '
                              f'{lost}: no longer hearing new participants, exiting',
                              file=sys.stderr, flush=True)
                        break
                self.audit()
                try:
                    conn, _ = listener.socket.accept()
                except TimeoutError:
                    continue
                with self._in_flight_lock:
                    self._in_flight.add(conn)
                threading.Thread(target=self.handle, args=(conn,), daemon=True).start()
        finally:
            listener.close()
            self._cut_in_flight()
        return 0

    def _cut_in_flight(self) -> None:
        """End the requests still being answered, with no answer: their commands ask the
        graph themselves (`query` returns None), rather than print what a closing session
        gave or failed to give."""
        self.stopping.set()
        with self._in_flight_lock:
            for conn in self._in_flight:
                with contextlib.suppress(OSError):
                    conn.shutdown(socket.SHUT_RDWR)


def serve(idle_timeout: float = IDLE_TIMEOUT, listener: Listener | None = None,
          owner: int | None = None) -> int:
    """Run a daemon for this process's graph in this process until idle or stopped."""
    from robot_lab.env import apply_ros_defaults

    apply_ros_defaults()
    if listener is None:
        listener = Listener.bind()
        if listener is None:
            return 0  # another daemon serves this graph
    return _Server(idle_timeout, owner).run(listener)


def _main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='python -m robot_lab.graph.daemon')
    parser.add_argument(_FLAG, dest='flag', action='store_true')
    parser.add_argument('--idle-timeout', type=float, default=IDLE_TIMEOUT)
    parser.add_argument('--listen-fd', type=int, default=None)
    parser.add_argument('--lock-fd', type=int, default=None)
    parser.add_argument('--owner', type=int, default=None)
    parser.add_argument('--nice', type=int, default=0)
    args = parser.parse_args(argv)
    if args.nice:
        os.nice(args.nice)
    listener = None
    if args.listen_fd is not None and args.lock_fd is not None:
        listener = Listener(socket.socket(fileno=args.listen_fd),
                            os.fdopen(args.lock_fd, 'a'), socket_path())
    code = serve(args.idle_timeout, listener, args.owner)
    # The exit closes the session (atexit), destroying its DDS entities, where Fast DDS 2.14
    # can deadlock: a receive thread holds the PDP mutex and waits for the event thread,
    # which waits for that mutex, while the destroying thread holds the GIL. s14T1 left a
    # daemon so, 20 minutes after its owner. faulthandler's watchdog is a C thread that needs
    # no GIL: past EXIT_WITHIN it prints where each thread is and ends the process.
    with contextlib.suppress(ValueError, AttributeError, OSError):  # no usable stderr
        faulthandler.dump_traceback_later(EXIT_WITHIN, exit=True)
    return code


if __name__ == '__main__':
    sys.exit(_main())
