"""A warm graph for one-shot commands: robot_lab's counterpart of the ros2 daemon.

A fresh `robot-lab node list` must start Python and rclpy and then wait for DDS discovery
before it can answer (≈ 1.7 s). ros2cli avoids that with a daemon: a long-lived process
whose participant already knows the graph, asked over a local socket. robot_lab does the
same. `robot-lab launch` starts one beside its nodes (it dies with the launcher, even after
`kill -9`), `robot-lab daemon start` starts one that exits after an idle timeout, and the
CLI's graph verbs ask it first and fall back to their own session when there is none.

One daemon per graph (user, ROS_DOMAIN_ID, discovery settings): its Unix socket lives in
`graph_dir()`, a per-user 0700 directory, and a lock file keeps it single. The client side
below imports neither rclpy nor the graph modules, so asking costs a few milliseconds.
The protocol is one JSON line each way.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import faulthandler
import fcntl
import functools
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import IO, Any

from robot_lab.env import switched_on
from robot_lab.errors import GraphError, RobotLabError
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

# `ros2 daemon start`'s daemon also exits after two hours without a request.
IDLE_TIMEOUT = 2 * 60 * 60.0
# How long a command waits for the daemon's answer before asking the graph itself: above
# the longest the daemon settles an answer (settler.Rules.names_timeout, counted in time the
# daemon ran), with room for a host that runs it only part of the time.
QUERY_TIMEOUT = 20.0
EXIT_WITHIN = 20.0  # s for the daemon's own exit, before its watchdog ends it (_main)
# Set (to anything but 0) to make every command use its own session, like --no-daemon.
NO_DAEMON_VARIABLE = 'ROBOT_LAB_NO_DAEMON'
# Set to 0 to keep graph verbs from starting a daemon when none runs (the test suite: a
# daemon per test domain would outlive each run by up to IDLE_TIMEOUT).
AUTOSTART_VARIABLE = 'ROBOT_LAB_DAEMON_AUTOSTART'
# The process whose end ends a daemon a command starts (default: the command's session).
OWNER_VARIABLE = 'ROBOT_LAB_DAEMON_OWNER'
# In the daemon's command line, so `pgrep -f robot-lab` finds it like the kit's other
# processes.
_FLAG = '--robot-lab-graph-daemon'
_SOCKET = 'daemon.sock'
_LOCK = 'daemon.lock'


def socket_path(env: Mapping[str, str] | None = None) -> Path:
    return graph_dir(env) / _SOCKET


def disabled() -> bool:
    """True when the user asked for no daemon (ROBOT_LAB_NO_DAEMON=1)."""
    return switched_on(NO_DAEMON_VARIABLE)


def _connect(path: Path, timeout: float) -> socket.socket | None:
    if not path.exists():
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(timeout)
    try:
        sock.connect(str(path))
    except OSError:  # a stale socket file: its daemon is gone
        sock.close()
        return None
    return sock


def query(op: str, *, timeout: float = QUERY_TIMEOUT, env: Mapping[str, str] | None = None,
          **params: Any) -> Any | None:
    """The daemon's answer to `op`, or None when no daemon serves this graph.

    None (rather than an error) also when the daemon does not answer within `timeout`, or
    does not know `op` (it is older than this client): the caller then asks the graph
    itself, which is slower but still right.
    """
    if disabled():
        return None
    sock = _connect(socket_path(env), timeout)
    if sock is None:
        return None
    with sock:
        try:
            sock.sendall(json.dumps({'op': op, **params}).encode() + b'\n')
            chunks = []
            while chunk := sock.recv(65536):
                chunks.append(chunk)
        except OSError:
            return None
    try:
        reply = json.loads(b''.join(chunks))
    except ValueError:
        return None
    if reply.get('unknown'):
        return None
    if 'error' in reply:
        raise GraphError(reply['error'], fix=reply.get('fix'))
    return reply.get('result')


def is_running(env: Mapping[str, str] | None = None) -> bool:
    """True when a daemon answers on this graph's socket."""
    sock = _connect(socket_path(env), 2.0)
    if sock is None:
        return False
    sock.close()
    return True


class Listener:
    """The daemon's bound socket and lock, made before the daemon process exists.

    A launcher binds it first thing (socket activation, as systemd does it): a
    `node list` typed while the daemon is still starting queues on the socket and gets a
    warm answer, instead of finding nothing and starting a cold session of its own.
    """

    def __init__(self, sock: socket.socket, lock: IO[str], path: Path) -> None:
        self.socket, self.lock, self.path = sock, lock, path
        self.closed = False

    @classmethod
    def bind(cls, env: Mapping[str, str] | None = None) -> Listener | None:
        """Bind this graph's socket; None if another daemon (or launcher) holds it."""
        try:
            directory = graph_dir(env, create=True)
            lock = open(directory / _LOCK, 'a')  # noqa: SIM115 - lives as long as the daemon
        except OSError:
            return None  # no runtime directory: commands use their own sessions
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            return None
        path = directory / _SOCKET
        with contextlib.suppress(FileNotFoundError):
            path.unlink()  # left by a daemon that was killed
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            sock.bind(str(path))
            sock.listen(64)
        except OSError:
            sock.close()
            lock.close()
            return None
        return cls(sock, lock, path)

    def fds(self) -> tuple[int, int]:
        return self.socket.fileno(), self.lock.fileno()

    def close(self, unlink: bool = True) -> None:
        """Close this process's copies (a daemon that inherited them keeps serving)."""
        if self.closed:
            return
        self.closed = True
        if unlink:
            with contextlib.suppress(OSError):
                self.path.unlink()
        self.socket.close()
        self.lock.close()


def start(*, detached: bool, idle_timeout: float = IDLE_TIMEOUT,
          env: Mapping[str, str] | None = None, listener: Listener | None = None,
          owner: int | None = None, nice: int = 0) -> subprocess.Popen[bytes]:
    """Start a daemon for the graph of `env` (default: this process's environment).

    `detached`: its own session, outliving the caller until its idle timeout (what
    `robot-lab daemon start` wants). Otherwise it is the caller's child and dies with it
    (what a launcher wants). `listener`: a socket the caller bound already (the daemon
    inherits it; the caller should then close its copy with `unlink=False`). `owner`: a
    process whose end (even by `kill -9`) ends the daemon too, e.g. the JupyterLab that
    `./kit start` runs. `nice`: a lower CPU priority, so a daemon started beside nodes does
    not slow their start-up. A second daemon for a graph that has one exits at once.
    """
    from robot_lab.env import ros_environment
    from robot_lab.process import spawn

    child_env = ros_environment(env)
    child_env.setdefault('OPENBLAS_NUM_THREADS', '1')  # see robot_lab.cli.main
    cmd = [sys.executable, '-m', 'robot_lab.graph.daemon', _FLAG,
           '--idle-timeout', f'{idle_timeout:g}']
    if owner is not None:
        cmd += ['--owner', str(owner)]
    if nice:
        cmd += ['--nice', str(nice)]
    fds: tuple[int, ...] = ()
    if listener is not None:
        fds = listener.fds()
        cmd += ['--listen-fd', str(fds[0]), '--lock-fd', str(fds[1])]
    if detached:
        return subprocess.Popen(cmd, env=child_env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True, pass_fds=fds)
    return spawn(cmd, env=child_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                 pass_fds=fds)


def start_for_later(env: Mapping[str, str] | None = None,
                    owner: int | None = None) -> subprocess.Popen[bytes] | None:
    """Start a daemon for this graph when none serves it, without waiting for it.

    What ros2cli does when a command finds no daemon: this command answers from its own
    session, the next ones get warm, complete answers (a participant started outside the
    kit announces itself only every 3 s, so a cold command can miss it). The daemon ends
    with `owner`: by default the process OWNER_VARIABLE names (a kernel names itself), else
    the caller's session (its terminal, a CI job); or after IDLE_TIMEOUT. It runs at a
    lower CPU priority than the command that started it.
    """
    if disabled() or os.environ.get(AUTOSTART_VARIABLE, '1') == '0':
        return None
    if owner is None:
        owner = _named_owner()
        if owner in (os.getpid(), 1):
            return None  # nobody to outlive: a daemon started now would only exit again
    if owner is None or not process_running(owner):
        return None
    listener = Listener.bind(env)
    if listener is None:
        return None  # a daemon (or a launch about to start one) holds this graph
    try:
        return start(detached=True, env=env, listener=listener, owner=owner, nice=10)
    except OSError:
        return None
    finally:
        listener.close(unlink=False)


def _named_owner() -> int | None:
    """The process a daemon started by a command should end with.

    A notebook's `!ros2 …` runs in a session of its own (IPython gives each `!` command a
    pseudo-terminal), led by a shell that ends with the command: a daemon that ended with
    that session ended at once, and every command in the notebook was cold. The kernel
    names itself in OWNER_VARIABLE (grading.setup).
    """
    named = os.environ.get(OWNER_VARIABLE, '').strip()
    if named.isdigit():
        return int(named)
    try:
        return os.getsid(0)
    except OSError:
        return None


def wait_until_running(timeout: float = 10.0, env: Mapping[str, str] | None = None,
                       proc: subprocess.Popen[bytes] | None = None) -> bool:
    """Poll until the daemon answers (or `proc`, the one being started, has exited)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if is_running(env):
            return True
        if proc is not None and proc.poll() is not None:
            return is_running(env)
        time.sleep(0.02)
    return False


def stop(timeout: float = 10.0, env: Mapping[str, str] | None = None) -> bool:
    """Ask the daemon to exit and wait until its socket is gone; False if none was running."""
    if not is_running(env):
        return False
    with contextlib.suppress(GraphError):
        query('stop', timeout=timeout, env=env)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and is_running(env):
        time.sleep(0.02)
    return True


# --- the daemon process ------------------------------------------------------------------

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
