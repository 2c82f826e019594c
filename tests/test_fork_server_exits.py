"""A forked node is the fork server's child: its exit status reaches the launcher over the
server's socket, with pidfds and without them (Linux before 5.3), and the launcher reports,
respawns and stops it as it would an exec'd child.

Small scripts with this interpreter's `#!` stand for a package's nodes: the server forks
them as it forks the kit's, and a test controls how they end.
"""

from __future__ import annotations

import errno
import os
import re
import signal
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest
from test_launch_run import Running

from robot_lab.env import ros_environment
from robot_lab.launch.fork_client import ForkedProcess, ForkServer
from robot_lab.launch.plan import LaunchPlan, ProcessSpec
from robot_lab.linux import capabilities

_SCRIPT = f"""#!{sys.executable}
import os, signal, sys, time
what = sys.argv[1]
if what == 'tell-parent':  # as a node that signals its parent (a hostile hand-in does)
    os.kill(os.getppid(), signal.SIGUSR1)
    sys.exit(0)
if what == 'stubborn':  # stops only for SIGKILL
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
if what in ('sleep', 'stubborn'):
    print(what, 'up', flush=True)
    time.sleep(120)
sys.exit(int(what))
"""


@pytest.fixture
def script(tmp_path: Path) -> str:
    path = tmp_path / 'lib' / 'demo' / 'ends'
    path.parent.mkdir(parents=True)
    path.write_text(_SCRIPT)
    path.chmod(0o755)
    return str(path)


def _spec(script: str, what: str, label: str, **kw: object) -> ProcessSpec:
    return ProcessSpec(cmd=[script, what], label=label, env={}, output='screen',
                       package='demo', executable='ends', **kw)  # type: ignore[arg-type]


def _pidfds(pid: int) -> int:
    folder = Path(f'/proc/{pid}/fd')
    count = 0
    for fd in folder.iterdir():
        try:
            count += os.readlink(fd) == 'anon_inode:[pidfd]'
        except OSError:
            continue
    return count


@pytest.fixture(params=['pidfd', 'switched off', 'ENOSYS'])
def server(request: pytest.FixtureRequest,
           monkeypatch: pytest.MonkeyPatch) -> Iterator[ForkServer]:
    """A fork server, with pidfds or without: switched off (here and, through
    ROBOT_LAB_DISABLE, in the server), or pidfd_open failing as on Linux before 5.3 or
    under a seccomp filter the probe did not meet."""
    off = ('pidfd',) if request.param == 'switched off' else ()
    if request.param == 'ENOSYS':
        def missing(pid: int, flags: int = 0) -> int:
            raise OSError(errno.ENOSYS, 'Function not implemented')

        monkeypatch.setattr(os, 'pidfd_open', missing)
    with capabilities.switched_off(*off):
        env = capabilities.child_environment(ros_environment())
        env.pop('PYTEST_CURRENT_TEST', None)
        forks = ForkServer(env)
        try:
            yield forks
        finally:
            forks.close()


def request_pidfds(server: ForkServer) -> bool:
    """Whether the handles of this test's server hold pidfds (the fixture's parameter)."""
    return capabilities.available('pidfd') and getattr(os.pidfd_open, '__name__', '') != 'missing'


def _start(server: ForkServer, script: str, what: str) -> ForkedProcess:
    env = capabilities.child_environment(ros_environment())
    env.pop('PYTEST_CURRENT_TEST', None)  # "(setup)" when the server started, now "(call)"
    node = server.start(_spec(script, what, what), env, None, sys.executable)
    assert node is not None, server.error
    return node


def test_exit_statuses_come_over_the_servers_socket(server: ForkServer, script: str) -> None:
    exits = _start(server, script, '3')
    assert psutil.Process(server.pid).is_running()
    assert exits.wait(30) == 3
    killed, stopped = _start(server, script, 'sleep'), _start(server, script, 'sleep')
    for node in (killed, stopped):
        assert node.stdout is not None and node.stdout.readline() == b'sleep up\n'
        assert psutil.Process(node.pid).ppid() == server.pid  # the server's, not ours
        with pytest.raises(ChildProcessError):  # so only the server can tell its status
            os.waitpid(node.pid, os.WNOHANG)
    assert killed.poll() is None
    assert _pidfds(os.getpid()) == (2 if request_pidfds(server) else 0)
    os.kill(killed.pid, signal.SIGKILL)  # from outside: only the server sees it
    assert killed.wait(30) == -signal.SIGKILL
    stopped.send_signal(signal.SIGTERM)
    assert stopped.wait(30) == -signal.SIGTERM


@pytest.mark.parametrize('server', ['pidfd', 'switched off'], indirect=True)
def test_nodes_die_with_a_server_that_is_killed(server: ForkServer, script: str) -> None:
    """The node's parent-death signal is tied to the server: the handle reports it killed."""
    node = _start(server, script, 'sleep')
    assert node.stdout is not None and node.stdout.readline() == b'sleep up\n'
    os.kill(server.pid, signal.SIGKILL)
    assert node.wait(30) == -signal.SIGKILL
    assert not psutil.pid_exists(node.pid) or psutil.Process(node.pid).status() == 'zombie'


def _lines(run: Running, pattern: str, count: int, timeout: float = 30.0) -> list[str]:
    """The first `count` lines of the launch matching `pattern`, once there are as many."""
    deadline = time.monotonic() + timeout
    found: list[str] = []
    seen = 0
    while len(found) < count:
        lines, seen = run.output.since(seen)
        found += [line.text for line in lines if re.search(pattern, line.text)]
        assert time.monotonic() < deadline, f'{found}:\n{run.text[-3000:]}'
        if len(found) < count:
            run.output.wait(seen, 0.2)
    return found[:count]


def test_the_launcher_reports_respawns_and_stops_forked_nodes(tmp_path: Path,
                                                              script: str) -> None:
    """Through the supervisor, pidfds off: exit codes and signals in launch's own lines,
    a respawn, and SIGINT -> SIGTERM -> SIGKILL escalation for a node that ignores both."""
    with capabilities.switched_off('pidfd'):
        plan = LaunchPlan(tmp_path / 'hand.launch.xml', [
            _spec(script, '3', 'exits-1', respawn=True, respawn_max_retries=1),
            _spec(script, 'sleep', 'sleeps-2'),
            _spec(script, 'stubborn', 'stubborn-3', sigterm_timeout=0.5, sigkill_timeout=0.5),
        ], [])
        run = Running(plan, tmp_path / 'log')
        try:
            pid = int(run.wait_for(r'\[sleeps-2\]: process started with pid \[(\d+)\]')[1])
            run.wait_for(r'\[sleeps-2\] sleep up')
            run.wait_for(r'\[stubborn-3\] stubborn up')
            forks = run.supervisor._forks
            assert forks is not None and forks.error is None
            assert psutil.Process(pid).ppid() == forks.pid
            os.kill(pid, signal.SIGKILL)
            run.wait_for(rf'\[sleeps-2\]: process has died \[pid {pid}, exit code -9, ')
            died = _lines(run, r'\[exits-1\]: process has died', 2)
            assert all(re.search(r'\[pid \d+, exit code 3, ', line) for line in died), died
        finally:
            run.stop()
    text = run.text
    assert text.count('[exits-1]: process started with pid') == 2, text
    assert re.search(r"process\[stubborn-3\] failed to terminate '0.5' seconds after receiving "
                     r"'SIGINT', escalating to 'SIGTERM'", text), text
    assert re.search(r"escalating to 'SIGKILL'", text), text
    assert re.search(r'\[stubborn-3\]: process has died \[pid \d+, exit code -9, ', text), text
    assert run.code == 0


def test_a_signal_a_node_sends_its_parent_reaches_the_launcher(server: ForkServer,
                                                              script: str) -> None:
    """An exec'd node's parent is the launcher: a forked node's signal to its parent (the
    server) is passed on to the launcher, here this test; one from anyone else is dropped,
    as a process group's Ctrl-C reaches the launcher itself."""
    got: list[int] = []
    previous = {s: signal.signal(s, lambda signum, _frame: got.append(signum))
                for s in (signal.SIGUSR1, signal.SIGUSR2)}
    try:
        assert _start(server, script, '0').wait(30) == 0  # the server is serving
        os.kill(server.pid, signal.SIGUSR2)  # not from a node: neither relayed nor fatal
        told = _start(server, script, 'tell-parent')
        assert told.wait(30) == 0
        deadline = time.monotonic() + 30
        while signal.SIGUSR1 not in got:
            assert time.monotonic() < deadline, f'no SIGUSR1 from the server: {got}'
            signal.sigtimedwait([], 0.05)  # a moment for the handler to run
        # A round trip through the server's loop: the SIGUSR2 was read before this node.
        assert _start(server, script, '0').wait(30) == 0
        assert got == [signal.SIGUSR1]
        assert psutil.Process(server.pid).is_running()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
