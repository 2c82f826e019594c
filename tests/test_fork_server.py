"""The launcher's fork server (ROBOT_LAB_FORK_SERVER=1): a forked node is the exec'd one.

Each test launches the kit's real nodes over real DDS, once exec'd and once forked, and
compares what a student (or a tool) can see of them: command line, environment, name,
executable, process group and session, signal dispositions, working directory, output,
exit codes, logs; and that none outlives its launcher, even after `kill -9`. One thing
differs: a forked node's parent is the server (test_fork_server_exits.py: its exit status
comes over the server's socket).
"""

from __future__ import annotations

import json
import os
import re
import signal
import sys
from pathlib import Path

import psutil
import pytest
from conftest import Proc, launched_nodes, run_cli
from test_launch_run import RUNNER, node_spec, py_spec

PY = sys.executable
SERVER = 'robot_lab.launch.fork_server'


def specs_json(*extra: str) -> str:
    specs = [node_spec('sensor_node', 'sensor', 1, *extra),
             node_spec('controller_node', 'controller', 2),
             node_spec('robot_node', 'robot', 3),
             py_spec('import time; print("plain", flush=True); time.sleep(120)', 4,
                     output='screen')]
    return json.dumps([vars(s) for s in specs])


def forked_from(pid: int, server: int) -> bool:
    """Whether `pid` was forked from `server`: it maps libc where the server does (an
    exec'd process gets its own random layout)."""
    def libc(p: int) -> set[str]:
        return {line.split('-')[0] for line in Path(f'/proc/{p}/maps').read_text().splitlines()
                if '/libc.so' in line}
    return libc(pid) == libc(server)


def status_fields(pid: int) -> dict[str, str]:
    fields = dict(line.split(':', 1) for line in Path(f'/proc/{pid}/status').read_text()
                  .splitlines() if ':' in line)
    return {k: fields[k].strip() for k in ('SigIgn', 'SigCgt', 'SigBlk', 'Uid', 'Gid')}


def looks(proc: psutil.Process, launcher: int) -> dict[str, object]:
    """What `ps` and /proc show of a process, as it would differ between exec and fork."""
    pid = proc.pid
    environ = Path(f'/proc/{pid}/environ').read_bytes().split(b'\0')
    return {
        'cmdline': Path(f'/proc/{pid}/cmdline').read_bytes(),
        'environ': [e for e in environ if not e.startswith(b'ROBOT_LAB_FORK_SERVER=')],
        'comm': Path(f'/proc/{pid}/comm').read_text(),
        'exe': os.readlink(f'/proc/{pid}/exe'),
        'cwd': os.readlink(f'/proc/{pid}/cwd'),
        'pgid_is_launchers': os.getpgid(pid) == os.getpgid(launcher),
        'sid': os.getsid(pid),
        **status_fields(pid),
    }


def launch(start, log_dir: Path, fork: bool, *extra: str) -> Proc:  # type: ignore[no-untyped-def]
    proc: Proc = start(PY, '-c', RUNNER, specs_json(*extra), '1',
                       env={'ROS_LOG_DIR': str(log_dir),
                            'ROBOT_LAB_FORK_SERVER': '1' if fork else '0'})
    return proc


def running(start, log_dir: Path, fork: bool) -> tuple[Proc, dict[str, psutil.Process]]:  # type: ignore[no-untyped-def]
    proc = launch(start, log_dir, fork)
    for started in ('Sensor node started', 'Controller node started', 'Robot node started',
                    r'\[python-4\] plain'):  # each process is itself by then
        proc.wait_for(started, 60)
    by_name: dict[str, psutil.Process] = {}
    launched = launched_nodes(proc.popen.pid)
    servers = [p for p in psutil.Process(proc.popen.pid).children() if p not in launched
               and SERVER in p.cmdline()]
    for child in launched + servers:
        args = child.cmdline()
        if any(SERVER in a for a in args):
            by_name['server'] = child
        elif len(args) > 1 and args[1].endswith('_node'):
            by_name[Path(args[1]).name] = child
        elif '-c' in args:
            by_name['python'] = child
    return proc, by_name


def stop(proc: Proc) -> str:
    proc.popen.send_signal(signal.SIGINT)
    assert proc.popen.wait(30) == 0, proc.output
    proc.wait_for(r'python-4\]: process has (finished cleanly|died)', 10)
    return proc.output


def test_forked_nodes_look_exactly_like_execd_ones(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    seen: dict[bool, dict[str, dict[str, object]]] = {}
    outputs: dict[bool, str] = {}
    for fork in (False, True):
        log_dir = tmp_path  # the same for both: it is in the environment compared
        proc, by_name = running(start, log_dir, fork)
        launcher = proc.popen.pid
        nodes = ('sensor_node', 'controller_node', 'robot_node')
        assert set(by_name) >= {*nodes, 'python'}, by_name
        server = by_name.get('server')
        if fork:  # the fork path was taken for the nodes, not for the plain python child
            assert server is not None and server.ppid() == launcher
            assert all(forked_from(by_name[n].pid, server.pid) for n in nodes)
            assert not forked_from(by_name['python'].pid, server.pid)
            assert all(by_name[n].ppid() == server.pid for n in nodes)  # reaped by it
            listed = run_cli('node', 'list', env={'ROS_LOG_DIR': str(log_dir)}).stdout.split()
            assert {'/sensor', '/controller', '/robot'} <= set(listed), listed
        else:
            assert server is None and all(by_name[n].ppid() == launcher for n in nodes)
        assert by_name['python'].ppid() == launcher
        seen[fork] = {name: looks(p, launcher) for name, p in by_name.items() if name != 'server'}
        pids = {name: p.pid for name, p in by_name.items()}
        outputs[fork] = stop(proc)
        for node in nodes:  # rcl's log file, named as for an exec'd `python SCRIPT`
            logs = list(log_dir.glob(f'python_{pids[node]}_*.log'))
            assert len(logs) == 1, sorted(p.name for p in log_dir.iterdir())
            assert 'started' in logs[0].read_text()
        assert not any(psutil.pid_exists(pid) for pid in pids.values())
    for name, exec_looks in seen[False].items():
        forked = seen[True][name]
        assert forked == exec_looks, (name, {k: (v, exec_looks[k]) for k, v in forked.items()
                                             if v != exec_looks[k]})

    def lines(text: str) -> list[str]:
        """The launcher's lines and each node's start-up line; numbers and order aside (how
        many periodic lines a node prints before it is stopped depends on timing)."""
        kept = {re.sub(r'\d+', 'N', ln) for ln in text.splitlines()
                if ln.startswith(('[INFO] [', '[WARNING] [', '[ERROR] [')) or 'started' in ln}
        return sorted(ln for ln in kept if 'log files can be found' not in ln)

    assert lines(outputs[True]) == lines(outputs[False])


def test_crash_prints_and_exits_as_execd(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """A node that fails at start: the same traceback and `process has died` line."""
    texts = {}
    for fork in (False, True):
        proc = launch(start, tmp_path / str(fork), fork, '-p', 'sensor_rate:=1000')
        proc.wait_for(r'sensor_node-1\]: process has died', 60)
        proc.wait_for(r'\[python-4\] plain')
        if fork:  # the server forked in this run (the sensor is gone: look at a sibling)
            proc.wait_for('Controller node started', 60)
            server = next(p for p in psutil.Process(proc.popen.pid).children()
                          if SERVER in p.cmdline())
            controller = next(p for p in launched_nodes(proc.popen.pid)
                              if '__node:=controller' in p.cmdline())
            assert forked_from(controller.pid, server.pid)
        stop(proc)
        text = proc.output
        died = re.search(r'sensor_node-1\]: process has died \[pid \d+, (exit code \d+)', text)
        assert died is not None, text
        crash = [ln for ln in text.splitlines() if ln.startswith('[sensor_node-1]')]
        texts[fork] = (died.group(1), [re.sub(r'\[\d+\.\d+\]', '[T]', ln) for ln in crash])
    assert texts[False][0] == 'exit code 1'
    assert texts[True] == texts[False]
    assert any('Traceback' in ln for ln in texts[True][1])


def test_kill_9_of_launcher_leaves_no_forked_node(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """The launcher's death kills the server (its parent-death signal), whose death kills
    each node (theirs)."""
    proc, by_name = running(start, tmp_path, fork=True)
    assert 'server' in by_name and by_name['sensor_node'].ppid() == by_name['server'].pid
    everything = list(by_name.values())
    os.kill(proc.popen.pid, signal.SIGKILL)
    proc.popen.wait(5)
    _, alive = psutil.wait_procs(everything, timeout=10)
    assert not alive, [p.cmdline() for p in alive]


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
def test_a_signal_to_a_forked_node_acts_as_on_a_fresh_one(start, tmp_path: Path,  # type: ignore[no-untyped-def]
                                                        signum: int) -> None:
    """SIGINT/SIGTERM straight to a node (not through the launcher): it ends cleanly, and
    the launcher reports the exit as it would for an exec'd node."""
    codes = {}
    for fork in (False, True):
        proc, by_name = running(start, tmp_path / str(fork), fork)
        assert 'sensor_node' in by_name, {k: p.cmdline() for k, p in by_name.items()}
        assert fork == ('server' in by_name and
                        forked_from(by_name['sensor_node'].pid, by_name['server'].pid))
        os.kill(by_name['sensor_node'].pid, signum)
        codes[fork] = proc.wait_for(r'sensor_node-1\]: process has (finished cleanly|died)',
                                    20).group(0)
        stop(proc)
    assert codes[True] == codes[False] == 'sensor_node-1]: process has finished cleanly'


def _shared_dirty_kb(pid: int) -> int:
    """Dirty pages the process shares: a forked node shares its server's imported heap."""
    for line in Path(f'/proc/{pid}/smaps_rollup').read_text().splitlines():
        if line.startswith('Shared_Dirty:'):
            return int(line.split()[1])
    raise AssertionError(f'no Shared_Dirty in /proc/{pid}/smaps_rollup')


@pytest.mark.parametrize('package', ['robot_lab', 'path'])
def test_a_launch_of_the_kits_package_starts_its_server_before_reading_the_file(  # type: ignore[no-untyped-def]
        start, tmp_path: Path, package: str) -> None:
    """`robot-lab launch robot_lab FILE` starts the server first (its imports overlap the
    parse); the nodes are forked from that one server. A launch named by path may be a
    student's: its server waits for the plan."""
    from robot_lab.launch.resolve import find_launch_file

    source = ['robot_lab', 'robot.launch.xml'] if package == 'robot_lab' else [
        str(find_launch_file('robot_lab', 'robot.launch.xml'))]
    proc = start('robot-lab', 'launch', '-d', *source,
                 env={'ROS_LOG_DIR': str(tmp_path), 'ROBOT_LAB_FORK_SERVER': '1'})
    when = ('before the launch file was read' if package == 'robot_lab'
            else 'for the first Python node')
    server = int(proc.wait_for(rf'fork server \[pid (\d+)\] started {when}', 60).group(1))
    proc.wait_for(r'\[robot\]: Status:', 60)
    servers = [p.pid for p in psutil.Process(proc.popen.pid).children()
               if SERVER in p.cmdline()]
    assert servers == [server]
    nodes = launched_nodes(proc.popen.pid)
    assert len(nodes) == 3 and all(_shared_dirty_kb(n.pid) > 4096 for n in nodes), [
        (n.cmdline(), _shared_dirty_kb(n.pid)) for n in nodes]
    proc.popen.send_signal(signal.SIGINT)
    assert proc.popen.wait(30) == 0, proc.output


def test_a_students_package_is_forked_and_looks_execd(start, seed_workspaces,  # type: ignore[no-untyped-def]
                                                       tmp_path: Path) -> None:
    """Lab 1.3's package, as a student builds it (console scripts with this venv's `#!`):
    its nodes are forked too, and look, log and stop as exec'd ones (their Ctrl-C
    tracebacks included: the seed's nodes do not catch KeyboardInterrupt)."""
    seen: dict[bool, dict[str, dict[str, object]]] = {}
    ends: dict[bool, list[str]] = {}
    nodes = ('sensor_node', 'controller_node', 'robot_node')
    for fork in (False, True):
        proc = start('robot-lab', 'launch', 'my_robot_system', 'robot.launch.xml',
                     'robot_name:=robot_alpha', cwd=seed_workspaces.fixed,
                     env={**seed_workspaces.fixed_env, 'ROS_LOG_DIR': str(tmp_path),
                          'ROBOT_LAB_FORK_SERVER': '1' if fork else '0'})
        proc.wait_for(r'\[robot\]: Status: OK', 60)
        launcher = proc.popen.pid
        by_name = {Path(p.cmdline()[1]).name: p for p in launched_nodes(launcher)}
        assert set(by_name) == set(nodes), {k: p.cmdline() for k, p in by_name.items()}
        servers = [p for p in psutil.Process(launcher).children() if SERVER in p.cmdline()]
        assert len(servers) == int(fork), [p.cmdline() for p in servers]
        assert all(forked_from(by_name[n].pid, servers[0].pid) for n in nodes) if fork else True
        parent = servers[0].pid if fork else launcher
        assert all(p.ppid() == parent for p in by_name.values())
        seen[fork] = {name: looks(p, launcher) for name, p in by_name.items()}
        for shown in seen[fork].values():  # the launch's own parameter file: a temp name
            shown['cmdline'] = re.sub(rb'launch_params_\w+', b'N', shown['cmdline'])  # type: ignore[call-overload]
        proc.popen.send_signal(signal.SIGINT)
        assert proc.popen.wait(30) == 0, proc.output[-3000:]
        ended = re.finditer(r'\[(\w+)-\d\]: process has (finished cleanly|died) \[pid \d+[^\]]*\]',
                            proc.output)
        ends[fork] = sorted(re.sub(r'pid \d+|launch_params_\w+', 'N', m.group(0)) for m in ended)
        assert sum('KeyboardInterrupt' in ln for ln in proc.output.splitlines()) >= 3, \
            proc.output[-3000:]
    assert len(ends[True]) == 3 and ends[True] == ends[False], ends
    for name, exec_looks in seen[False].items():
        forked = seen[True][name]
        assert forked == exec_looks, (name, {k: (v, exec_looks[k]) for k, v in forked.items()
                                             if v != exec_looks[k]})
