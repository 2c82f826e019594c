"""The Linux layer (robot_lab/linux/): sock_diag against a fake netlink peer and with two
threads dumping at once, pidfds switched off, each capability's switch, the
doctor's table, and a launch and a cold `node list` with each capability off."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import psutil
import pytest
from conftest import BIN, Proc, run_cli

from robot_lab.launch import fork_client
from robot_lab.linux import capabilities, pidfd, sock_diag
from robot_lab.linux.sock_diag import HEADER, MESSAGE_SIZE, NLMSG_DONE, NLMSG_ERROR

NODES = ['/controller', '/robot', '/sensor']


# --- sock_diag against a fake netlink peer ------------------------------------------------

def _message(kind: int, sequence: int, body: bytes = b'') -> bytes:
    length = HEADER.size + len(body)
    return HEADER.pack(length, kind, 2, sequence, 0) + body + b'\0' * (-length % 4)


def _row(sequence: int, port: int, inode: int, drops: int = 0) -> bytes:
    """An inet_diag_msg for a socket bound to `port`, with its SKMEMINFO attribute."""
    body = bytearray(MESSAGE_SIZE)
    struct.pack_into('>H', body, 4, port)
    struct.pack_into('=I', body, MESSAGE_SIZE - 4, inode)
    meminfo = struct.pack('=9I', *([0] * 8), drops)
    attribute = struct.pack('=HH', 4 + len(meminfo), 7) + meminfo
    return _message(sock_diag.SOCK_DIAG_BY_FAMILY, sequence, bytes(body) + attribute)


Script = Callable[[int], list[bytes]]


class FakePeer:
    """The kernel's end of a netlink socket, on a real socket pair (so the dump's own
    timeouts apply): reads the dump's request, then sends the batches `script(sequence)`
    returns; closes its end afterwards if `close`, else leaves the dump waiting."""

    def __init__(self, script: Script, close: bool = False,
                 before_reply: Callable[[], object] = lambda: None) -> None:
        self.ours, self.theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self.script, self.close, self.before_reply = script, close, before_reply
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def connect(self) -> socket.socket:
        return self.ours

    def _serve(self) -> None:
        request = self.theirs.recv(4096)
        sequence = HEADER.unpack_from(request)[3]
        self.before_reply()
        for batch in self.script(sequence):
            self.theirs.send(batch)
        if self.close:
            self.theirs.close()

    def end(self) -> None:
        self.thread.join(5)
        self.theirs.close()


def _dump(peer: FakePeer, timeout: float = 2.0) -> list[int]:
    try:
        return sorted(s.port for s in sock_diag.dump(socket.AF_INET, timeout=timeout,
                                                      connect=peer.connect))
    finally:
        peer.end()


def test_a_dump_takes_only_its_own_replies_among_a_second_dumps() -> None:
    """A second dump's messages (its DONE too) arrive in the same batches: skipped, and
    the dump ends at its own DONE."""
    def script(seq: int) -> list[bytes]:
        other = seq + 1000
        return [_row(seq, 7400, 1) + _row(other, 7402, 2) + _message(NLMSG_DONE, other),
                _row(other, 7406, 4) + _row(seq, 7404, 3, drops=5) + _message(NLMSG_DONE, seq)]

    assert _dump(FakePeer(script)) == [7400, 7404]


def test_a_truncated_dump_is_an_error_not_a_hang() -> None:
    ended = FakePeer(lambda seq: [_row(seq, 7400, 1)], close=True)
    with pytest.raises(OSError, match='ended without its last message'):
        _dump(ended)
    cut = FakePeer(lambda seq: [_row(seq, 7400, 1)[:-8]])
    with pytest.raises(OSError, match='malformed'):
        _dump(cut)


def test_an_error_reply_is_an_error() -> None:
    def script(seq: int) -> list[bytes]:
        return [_message(NLMSG_ERROR, seq, struct.pack('=i', -errno.EOPNOTSUPP) + b'\0' * 16)]

    with pytest.raises(OSError) as raised:
        _dump(FakePeer(script))
    assert raised.value.errno == errno.EOPNOTSUPP


def test_a_dump_that_stalls_times_out() -> None:
    began = time.monotonic()
    with pytest.raises(OSError):
        _dump(FakePeer(lambda seq: [_row(seq, 7400, 1)]), timeout=0.2)
    assert time.monotonic() - began < 2.0


def test_two_dumps_at_once_each_end_at_their_own_done() -> None:
    """Two threads' dumps, each peer answering only once both requests are out (so each
    dump's replies come after the other dump began): both end, each with its sockets."""
    both_asked = threading.Barrier(2, timeout=5)
    results: dict[int, list[int]] = {}

    def run(port: int) -> None:
        peer = FakePeer(lambda seq: [_row(seq, port, port), _message(NLMSG_DONE, seq)],
                        before_reply=both_asked.wait)
        results[port] = _dump(peer)

    threads = [threading.Thread(target=run, args=(port,), daemon=True) for port in (7400, 7402)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert results == {7400: [7400], 7402: [7402]}


def test_two_threads_dumping_the_kernel_at_once() -> None:
    """The real kernel, two threads dumping in a loop with the GIL handed over as often as
    it can be: each dump ends and finds the socket bound here. (A sequence number shared
    by the threads made one skip its DONE and wait in recv forever.)"""
    try:
        sock_diag.dump(socket.AF_INET)
    except OSError as error:
        pytest.skip(f'no UDP sock_diag here ({error}); the fake peer tests cover it')
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as bound:
        bound.bind(('127.0.0.1', 0))
        port = bound.getsockname()[1]
        found: list[bool] = []

        def dumps() -> None:
            found.extend(port in {s.port for s in sock_diag.dump(socket.AF_INET)}
                         for _ in range(1000))

        interval = sys.getswitchinterval()
        sys.setswitchinterval(1e-6)
        try:
            threads = [threading.Thread(target=dumps, daemon=True) for _ in range(2)]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join(20)
        finally:
            sys.setswitchinterval(interval)
        assert not any(t.is_alive() for t in threads), 'a dump never ended'
        assert found == [True] * 2000


def test_the_socket_table_comes_from_proc_without_sock_diag(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Switched off, no netlink socket is opened; failing, the dump gives way to /proc."""
    def refused() -> socket.socket:
        raise PermissionError(errno.EPERM, 'netlink refused')

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as bound:
        bound.bind(('127.0.0.1', 0))
        port = bound.getsockname()[1]
        monkeypatch.setattr(sock_diag, '_netlink', refused)
        assert port in {s.port for s in sock_diag.udp_sockets()}
        monkeypatch.setattr(sock_diag, '_netlink', lambda: pytest.fail('netlink opened'))
        with capabilities.switched_off('sock_diag'):
            assert port in {s.port for s in sock_diag.udp_sockets()}


# --- pidfds -----------------------------------------------------------------------------

def test_switched_off_pidfds_are_not_opened() -> None:
    assert pidfd.open_pidfd(os.getpid()) is not None or not capabilities.available('pidfd')
    with capabilities.switched_off('pidfd'):
        assert pidfd.open_pidfd(os.getpid()) is None


# --- the fork server ------------------------------------------------------------------

def test_a_fork_server_that_stops_answering_is_ended_and_the_node_execd(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Its socket is read with a timeout: a server stuck (here: stopped) is killed, and the
    launcher execs the node instead of waiting forever."""
    from robot_lab.env import ros_environment
    from robot_lab.launch.plan import ProcessSpec
    from robot_lab.pkg.index import find_executable

    monkeypatch.setattr(fork_client, '_REPLY_TIMEOUT', 0.5)
    env = ros_environment()
    server = fork_client.ForkServer(env)
    try:
        script = str(find_executable('robot_lab', 'sensor_node'))
        spec = ProcessSpec(cmd=[script], label='sensor_node-1', env={}, package='robot_lab')
        assert server._warm(), server.error  # imported, ready to fork
        os.kill(server.pid, signal.SIGSTOP)
        began = time.monotonic()
        assert server.start(spec, env, None, sys.executable) is None
        assert time.monotonic() - began < 10
        assert server.error is not None and 'did not answer' in server.error
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(server.pid, signal.SIGCONT)
        server.discard()


_THREAD_CHECK = """
import faulthandler, json, socket
from robot_lab.launch import fork_server

class NoFork:
    def fork(self):
        raise RuntimeError('would fork now')

ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
server = fork_server._Server(theirs, NoFork().fork)
for step in ('alone', 'with a C thread'):
    if step != 'alone':
        faulthandler.dump_traceback_later(600)  # a native thread threading never sees
    ours.send(b'{}')
    server.request()
    print(step, json.loads(ours.recv(4096))['error'], flush=True)
faulthandler.cancel_dump_traceback_later()
"""


def test_the_fork_server_refuses_to_fork_beside_a_native_thread() -> None:
    """A thread a library started (not Python's) could hold a lock the child would never
    see released: the server counts the kernel's threads, not only Python's."""
    done = subprocess.run([sys.executable, '-c', _THREAD_CHECK], capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.stdout.splitlines() == [
        'alone RuntimeError: would fork now',
        'with a C thread RuntimeError: the fork server has threads: forking it is unsafe',
    ], done.stdout + done.stderr


# --- namespaces ---------------------------------------------------------------------------

_NAMESPACES = """
import os, sys, tempfile
from robot_lab.linux import namespaces as ns, procfs
uid, gid = os.getuid(), os.getgid()
try:
    ns.unshare(ns.CLONE_NEWUSER | ns.CLONE_NEWNS)
except OSError as error:
    print('refused', error)
    sys.exit(0)
print('initial', ns.in_initial_user_namespace())
ns.map_ids(0, 0, uid, gid)
print('uid', os.getuid())
ns.mount(None, '/', None, ns.MS_REC | ns.MS_PRIVATE)
folder = tempfile.mkdtemp()
ns.mount('tmpfs', folder, 'tmpfs', ns.MS_NOSUID | ns.MS_NODEV, 'size=1m')
print('mounted', folder in procfs.mount_points())
ns.unmount(folder, detach=True)
print('unmounted', folder not in procfs.mount_points())
os.rmdir(folder)
ns.drop_capabilities()
print('CapEff', [l.split()[1] for l in open('/proc/self/status') if l.startswith('CapEff')][0])
"""


def test_a_user_namespace_its_ids_mounts_and_no_capabilities() -> None:
    """What the grader's confinement asks of the layer, in a process of its own."""
    done = subprocess.run([sys.executable, '-c', _NAMESPACES], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    if done.stdout.startswith('refused'):
        pytest.skip(f'no user namespaces here: {done.stdout.strip()}')
    assert done.stdout.split('\n')[:5] == ['initial False', 'uid 0', 'mounted True',
                                           'unmounted True', 'CapEff 0000000000000000']


def test_what_refuses_namespaces_is_read_by_the_layer(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ubuntu 24.04's AppArmor rule, Debian's old switch, a zero limit, Docker's seccomp
    filter: each read from /proc by the layer, each its own advice from the grader."""
    from robot_lab.grading.package import containment
    from robot_lab.linux import namespaces, procfs

    settings = {'kernel.apparmor_restrict_unprivileged_userns': '1',
                'kernel.unprivileged_userns_clone': '0', 'user.max_net_namespaces': '0',
                'user.max_user_namespaces': '0', 'user.max_pid_namespaces': '15000'}
    monkeypatch.setattr(procfs, 'sysctl', settings.get)
    monkeypatch.setattr(procfs, 'status', lambda pid=None: {'Seccomp': '2'})
    found = namespaces.restrictions()
    assert found == namespaces.Restrictions(apparmor=True, userns_clone_off=True,
                                            zero_limits=('net', 'user'), seccomp=True)
    monkeypatch.setattr(os, 'geteuid', lambda: 1000)
    advice = ' '.join(containment._advice())
    for said in ('kernel.apparmor_restrict_unprivileged_userns=0',
                 'kernel.unprivileged_userns_clone=1',
                 'user.max_net_namespaces=15000 user.max_user_namespaces=15000',
                 'seccomp=unconfined'):
        assert said in advice, advice
    monkeypatch.setattr(os, 'geteuid', lambda: 0)  # root needs no user namespace
    advice = ' '.join(containment._advice())
    assert 'apparmor' not in advice and 'user.max_user_namespaces' not in advice, advice
    monkeypatch.setattr(procfs, 'sysctl', lambda name: None)  # an older kernel: none of them
    monkeypatch.setattr(procfs, 'status', lambda pid=None: {})
    assert namespaces.restrictions() == namespaces.Restrictions(False, False, (), False)


# --- nothing reaches around the layer ---------------------------------------------------

_REACHES = re.compile(r'^\s*(import ctypes|from ctypes)|ctypes\.|[\'"]/proc', re.MULTILINE)


def test_nothing_outside_the_layer_calls_ctypes_or_reads_proc() -> None:
    root = Path(__file__).resolve().parent.parent
    found = sorted(str(path.relative_to(root)) for path in (root / 'robot_lab').rglob('*.py')
                   if not path.is_relative_to(root / 'robot_lab' / 'linux')
                   and _REACHES.search(path.read_text(encoding='utf-8')))
    assert found == [], f'use robot_lab.linux instead: {found}'


def test_procfs_reads_status_and_sysctls() -> None:
    from robot_lab.linux import procfs

    assert procfs.status()['Pid'] == str(os.getpid())
    assert procfs.sysctl('kernel.pid_max') == Path('/proc/sys/kernel/pid_max').read_text().strip()
    assert procfs.sysctl('kernel.no_such_setting') is None


# --- switches and the doctor --------------------------------------------------------------

def test_switches_by_variable_and_by_block(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(capabilities.DISABLE_VARIABLE, ' sock_diag , fork_server')
    assert capabilities.disabled('sock_diag') and capabilities.disabled('fork_server')
    assert not fork_client.enabled()
    assert capabilities.reason('sock_diag') is not None
    monkeypatch.delenv(capabilities.DISABLE_VARIABLE)
    with capabilities.switched_off('pidfd'), capabilities.switched_off('pidfd'):
        assert not capabilities.available('pidfd')
        assert capabilities.child_environment({})[capabilities.DISABLE_VARIABLE] == 'pidfd'
    assert not capabilities.disabled('pidfd')
    with pytest.raises(KeyError, match='no capability'):
        capabilities.disabled('pidfds')


def test_a_capability_switched_off_here_is_off_in_the_children_spawned() -> None:
    from robot_lab.process import spawn

    show = [sys.executable, '-c', 'import os; print(os.environ.get("ROBOT_LAB_DISABLE"))']
    with capabilities.switched_off('pidfd'):
        child = spawn(show)
    assert child.communicate(timeout=30)[0].decode().strip() == 'pidfd'


def test_the_doctor_prints_each_capability_and_its_fallback() -> None:
    every = ','.join(capabilities.CAPABILITIES)
    result = run_cli('doctor', env={capabilities.DISABLE_VARIABLE: every})
    assert 'Linux capabilities' in result.stdout, result.stdout + result.stderr
    for cap in capabilities.CAPABILITIES.values():
        assert re.search(rf'^  {cap.name} +no +{re.escape(cap.fallback)}$', result.stdout,
                         re.MULTILINE), result.stdout


# --- each capability off: a launch and a cold `node list` ----------------------------------

def _fds(pid: int) -> list[str]:
    folder = Path(f'/proc/{pid}/fd')
    found = []
    for fd in folder.iterdir():
        try:
            found.append(os.readlink(fd))
        except OSError:
            continue
    return found


@pytest.fixture(params=sorted(capabilities.CAPABILITIES))
def launch_without(request: pytest.FixtureRequest) -> Iterator[tuple[str, Proc]]:
    name = request.param
    env = {**os.environ, capabilities.DISABLE_VARIABLE: name}
    proc = Proc([str(BIN / 'robot-lab'), 'launch', 'robot_lab', 'robot.launch.xml'], env=env)
    try:
        for line in ('Sensor node started', 'Controller node started', 'Robot node started'):
            proc.wait_for(line, timeout=60)
        yield name, proc
    finally:
        proc.stop()


def test_a_launch_and_a_cold_node_list_work_with_a_capability_off(
        launch_without: tuple[str, Proc]) -> None:
    name, proc = launch_without
    off = {capabilities.DISABLE_VARIABLE: name, 'ROBOT_LAB_DEBUG_DISCOVERY': '1'}
    listed = run_cli('node', 'list', '--no-daemon', env=off)
    assert listed.returncode == 0, listed.stderr
    assert listed.stdout.split() == NODES, listed.stdout + listed.stderr
    launcher = proc.popen.pid
    if name == 'fork_server':  # every node exec'd: no server beside them
        assert not [p for p in psutil.Process(launcher).children(recursive=True)
                    if 'robot_lab.launch.fork_server' in p.cmdline()]
    if name == 'pidfd':  # the launcher polls its children
        assert 'anon_inode:[pidfd]' not in _fds(launcher)
    if name == 'sock_diag':  # the host's count still read, from /proc/net/udp
        counted = re.search(r'ports=(\d+)', listed.stderr)
        assert counted is not None and int(counted[1]) >= 4, listed.stderr
