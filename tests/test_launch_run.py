"""The supervisor with hand-built plans: output lines, routing, exits, respawn, shutdown.

Real processes throughout: the kit's three nodes over real DDS, and small Python
children whose behaviour (exit codes, ignored signals) a test needs to control.
"""

from __future__ import annotations

import io
import itertools
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest
from conftest import Proc, launched_nodes

from robot_lab.errors import ParamFileError
from robot_lab.launch.output import LaunchOutput
from robot_lab.launch.parameters import check_param_files
from robot_lab.launch.plan import (
    LaunchPlan,
    LogAction,
    ProcessSpec,
    ShutdownAction,
    TimerSpec,
)
from robot_lab.launch.supervisor import Supervisor
from robot_lab.pkg.index import find_executable

PY = sys.executable


def node_spec(exe: str, name: str, n: int, *extra: str, output: str = 'screen',
              **kw: object) -> ProcessSpec:
    """A ProcessSpec for one of the kit's nodes, as launch_ros would build it."""
    cmd = [str(find_executable('robot_lab', exe)), '--ros-args', '-r', f'__node:={name}', *extra]
    return ProcessSpec(cmd=cmd, label=f'{exe}-{n}', env={}, output=output, node_name=name,
                       package='robot_lab', executable=exe, **kw)  # type: ignore[arg-type]


def py_spec(code: str, n: int, **kw: object) -> ProcessSpec:
    return ProcessSpec(cmd=[PY, '-c', code], label=f'python-{n}', env={},
                       executable='python', **kw)  # type: ignore[arg-type]


class Running:
    """A Supervisor running in a thread of the test, its screen captured."""

    def __init__(self, plan: LaunchPlan, log_dir: Path) -> None:
        self.screen = io.StringIO()
        self.output = LaunchOutput(self.screen, log_dir=log_dir)
        self.supervisor = Supervisor(plan, self.output, noninteractive=True)
        self.code: int | None = None
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()
        assert self.supervisor.started.wait(15)

    def _run(self) -> None:
        self.output.open()
        try:
            self.code = self.supervisor.run()
        finally:
            self.output.close()

    @property
    def text(self) -> str:
        return self.screen.getvalue()

    def wait_for(self, pattern: str, timeout: float = 15.0) -> re.Match[str]:
        deadline = time.monotonic() + timeout
        seen = 0
        while True:
            lines, seen_now = self.output.since(seen)
            for line in lines:
                found = re.search(pattern, line.text)
                if found:
                    return found
            seen = seen_now
            if time.monotonic() > deadline:
                raise AssertionError(f'no line matching {pattern!r}:\n{self.text[-4000:]}')
            self.output.wait(seen, 0.2)

    def join(self, timeout: float = 30.0) -> int:
        self.thread.join(timeout)
        assert not self.thread.is_alive(), f'launch did not end:\n{self.text[-3000:]}'
        assert self.code is not None
        return self.code

    def stop(self) -> None:
        self.supervisor.shutdown()
        self.join()


@pytest.fixture
def launches(tmp_path: Path) -> Iterator[list[Running]]:
    started: list[Running] = []
    yield started
    for running in started:
        if running.thread.is_alive():
            running.stop()


@pytest.fixture
def run_plan(tmp_path: Path, launches: list[Running]):  # type: ignore[no-untyped-def]
    def _run(*actions: object) -> Running:
        plan = LaunchPlan(tmp_path / 'hand.launch.xml', list(actions), [])  # type: ignore[arg-type]
        running = Running(plan, tmp_path / f'log{len(launches)}')
        launches.append(running)
        return running

    return _run


def test_output_lines_log_dir_and_routing(run_plan, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    code = 'import sys; print("to-stdout"); print("to-stderr", file=sys.stderr); sys.exit({})'
    run = run_plan(py_spec(code.format(0), 1, output='log'),
                   py_spec(code.format(3), 2, output='screen'))
    assert run.join() == 0
    lines = run.text.splitlines()
    log_dir = run.output.log_dir
    assert lines[0] == f'[INFO] [launch]: All log files can be found below {log_dir}'
    assert lines[1] == '[INFO] [launch]: Default logging verbosity is set to INFO'
    pid1 = int(re.search(r'\[INFO\] \[python-1\]: process started with pid \[(\d+)\]',
                         run.text).group(1))  # type: ignore[union-attr]
    pid2 = run.supervisor.records[1].pid
    assert f'[INFO] [python-1]: process has finished cleanly [pid {pid1}]' in lines
    cmd = f'{PY} -c ' + code.format(3)
    assert f"[ERROR] [python-2]: process has died [pid {pid2}, exit code 3, cmd '{cmd}']." in lines
    # output='log': stdout only to the log file, stderr on screen; 'screen': both on screen.
    assert '[python-1] to-stderr' in lines
    assert '[python-1] to-stdout' not in lines
    assert '[python-2] to-stdout' in lines and '[python-2] to-stderr' in lines
    launch_log = (log_dir / 'launch.log').read_text()
    assert re.search(r'^\d+\.\d{7} \[python-1\] to-stdout$', launch_log, re.M)
    assert re.search(r'^\d+\.\d{7} \[INFO\] \[launch\]: All log files', launch_log, re.M)
    assert 'to-stdout' in (log_dir / 'python-1.log').read_text()
    assert [r.state for r in run.supervisor.records] == ['finished', 'died']
    assert [r.returncode for r in run.supervisor.records] == [0, 3]


def test_log_dir_follows_ros_log_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv('ROS_LOG_DIR', str(tmp_path / 'logs'))
    out = LaunchOutput(None)
    assert out.log_dir.parent == tmp_path / 'logs'
    assert re.fullmatch(r'\d{4}-\d\d-\d\d-\d\d-\d\d-\d\d-\d{6}-.+-\d+', out.log_dir.name)
    assert (tmp_path / 'logs' / 'latest').resolve() == out.log_dir


def test_seed_nodes_run_and_stop_cleanly(run_plan) -> None:  # type: ignore[no-untyped-def]
    run = run_plan(node_spec('sensor_node', 'sensor', 1),
                   node_spec('controller_node', 'controller', 2),
                   node_spec('robot_node', 'robot', 3, '-p', 'robot_name:=robot_alpha'))
    run.wait_for(r'^\[sensor_node-1\] \[INFO\] \[[\d.]+\] \[sensor\]: '
                 r'Sensor node started \(rate: 10 Hz\)$')
    run.wait_for(r'\[controller\]: Controller node started$')
    run.wait_for(r'\[robot\]: Robot node started: robot_alpha$')
    run.wait_for(r'^\[robot_node-3\] .*\[robot\]: Status: OK \(temp: 2\d\.\d°C\)$')
    run.stop()
    for n, label in enumerate(['sensor_node-1', 'controller_node-2', 'robot_node-3']):
        pid = run.supervisor.records[n].pid
        assert f"[INFO] [{label}]: sending signal 'SIGINT' to process[{label}]" in run.text
        assert re.search(rf'\[{label}\]: process has (finished cleanly|died) \[pid {pid}[],]',
                         run.text)
        assert not psutil.pid_exists(pid) or psutil.Process(pid).status() == 'zombie'
    # The sensor subscribes to nothing, so nothing can race its SIGINT: it ends cleanly.
    # (The others can die of an rclpy RuntimeError when SIGINT lands mid-take; nodes/base.py.)
    sensor_pid = run.supervisor.records[0].pid
    assert f'[INFO] [sensor_node-1]: process has finished cleanly [pid {sensor_pid}]' in run.text


def test_crash_leaves_siblings_running(run_plan) -> None:  # type: ignore[no-untyped-def]
    run = run_plan(node_spec('sensor_node', 'sensor', 1),
                   node_spec('controller_node', 'controller', 2),
                   node_spec('robot_node', 'robot', 3),
                   py_spec('import sys, time; time.sleep(1.0); sys.exit(7)', 4))
    run.wait_for(r'\[ERROR\] \[python-4\]: process has died \[pid \d+, exit code 7')
    # The siblings carry on: the robot keeps reporting the controller's status.
    _, mark = run.output.since(0)
    run.wait_for(r'Robot node started')
    deadline = time.monotonic() + 10
    while not any('Status: OK' in line.text for line in run.output.since(mark)[0]):
        assert time.monotonic() < deadline, run.text[-3000:]
        run.output.wait(run.output.count, 0.5)
    assert [r.state for r in run.supervisor.records] == ['running'] * 3 + ['died']
    run.stop()
    assert run.supervisor.records[0].state == 'finished'
    assert all(r.state in ('finished', 'died') for r in run.supervisor.records)


def test_respawn_with_delay_and_max_retries(run_plan) -> None:  # type: ignore[no-untyped-def]
    spec = py_spec('import sys; print("up", file=sys.stderr); sys.exit(1)', 1,
                   respawn=True, respawn_delay=0.3, respawn_max_retries=2)
    run = run_plan(spec)
    assert run.join() == 0  # all attempts used: the launch ends by itself
    started = re.findall(r'\[INFO\] \[python-1\]: process started with pid \[(\d+)\]', run.text)
    died = re.findall(r'process has died \[pid (\d+), exit code 1', run.text)
    assert len(started) == 3 and started == died
    assert len(set(started)) == 3
    stamps = [line.time for line in run.output.lines() if 'process started' in line.text]
    assert all(b - a >= 0.3 for a, b in itertools.pairwise(stamps))


def test_respawn_stops_at_shutdown(run_plan) -> None:  # type: ignore[no-untyped-def]
    spec = py_spec('import sys; sys.exit(2)', 1, respawn=True, respawn_delay=30.0)
    run = run_plan(spec)
    run.wait_for(r'process has died')
    assert run.supervisor.records[0].state == 'respawning'
    run.stop()  # a pending respawn must not keep the launch alive for 30 s
    assert run.text.count('process started') == 1


def test_on_exit_shutdown_stops_the_others(run_plan) -> None:  # type: ignore[no-untyped-def]
    # The required process ends once the sensor is up: a SIGINT that reached the sensor
    # while Python was still importing would end it 'died' (a KeyboardInterrupt), as it
    # would any Python node (CI under load: after a fixed 1 s sleep it sometimes did).
    run = run_plan(node_spec('sensor_node', 'sensor', 1),
                   py_spec("import robot_lab; robot_lab.wait_for_nodes(['/sensor'], "
                           'timeout=60)', 2, on_exit='shutdown'))
    assert run.join() == 0
    assert '[INFO] [launch]: process[python-2] was required: shutting down launched system' \
        in run.text
    assert "[INFO] [sensor_node-1]: sending signal 'SIGINT' to process[sensor_node-1]" in run.text
    assert run.supervisor.records[0].state == 'finished'


def test_timer_log_and_shutdown_actions(run_plan) -> None:  # type: ignore[no-untyped-def]
    run = run_plan(LogAction('starting'),
                   py_spec('import time; time.sleep(60)', 1),
                   TimerSpec(0.4, [LogAction('timer fired', 'WARNING'), ShutdownAction('done')]))
    assert run.join() == 0
    lines = run.text.splitlines()
    assert '[INFO] [launch.user]: starting' in lines
    assert '[WARNING] [launch.user]: timer fired' in lines
    fired = next(ln.time for ln in run.output.lines() if 'timer fired' in ln.text)
    began = next(ln.time for ln in run.output.lines() if 'starting' in ln.text)
    assert fired - began >= 0.4
    assert "sending signal 'SIGINT' to process[python-1]" in run.text


def test_sigint_sigterm_sigkill_escalation(run_plan) -> None:  # type: ignore[no-untyped-def]
    stubborn = ('import signal, sys, time\n'
                'signal.signal(signal.SIGINT, signal.SIG_IGN)\n'
                'signal.signal(signal.SIGTERM, signal.SIG_IGN)\n'
                'print("ignoring", file=sys.stderr, flush=True)\n'
                'time.sleep(120)\n')
    run = run_plan(py_spec(stubborn, 1, sigterm_timeout=0.5, sigkill_timeout=0.5))
    run.wait_for(r'\[python-1\] ignoring')
    began = time.monotonic()
    run.stop()
    took = time.monotonic() - began
    pid = run.supervisor.records[0].pid
    expected = [
        "[INFO] [python-1]: sending signal 'SIGINT' to process[python-1]",
        "[ERROR] [python-1]: process[python-1] failed to terminate '0.5' seconds after "
        "receiving 'SIGINT', escalating to 'SIGTERM'",
        "[INFO] [python-1]: sending signal 'SIGTERM' to process[python-1]",
        "[ERROR] [python-1]: process[python-1] failed to terminate '1.0' seconds after "
        "receiving 'SIGTERM', escalating to 'SIGKILL'",
        "[INFO] [python-1]: sending signal 'SIGKILL' to process[python-1]",
    ]
    lines = run.text.splitlines()
    positions = [lines.index(line) for line in expected]
    assert positions == sorted(positions)
    assert re.search(rf'\[ERROR\] \[python-1\]: process has died \[pid {pid}, exit code -9, ',
                     run.text)
    assert 0.9 <= took < 10


def test_flat_param_file_refused_before_start(tmp_path: Path) -> None:
    flat = tmp_path / 'robot_params.yaml'
    flat.write_text('# Sensor parameters\nsensor_rate: 10\nnoise_level: 0.1\n')
    plan = LaunchPlan(tmp_path / 'x.launch.xml',
                      [node_spec('sensor_node', 'sensor', 1, '--params-file', str(flat),
                                 param_files=[str(flat)])], [])
    with pytest.raises(ParamFileError) as err:
        check_param_files(plan)
    assert 'robot_params.yaml' in str(err.value) and 'ros__parameters' in str(err.value)


# --- the launcher as its own process: Ctrl-C and kill -9 -----------------------------------

RUNNER = r"""
import json, sys
from pathlib import Path
from robot_lab.cli.launch import run
from robot_lab.launch.plan import LaunchPlan, ProcessSpec
specs = [ProcessSpec(**d) for d in json.loads(sys.argv[1])]
sys.exit(run(LaunchPlan(Path('hand.launch.xml'), specs, []), noninteractive=sys.argv[2] == '1'))
"""


def three_nodes_json() -> str:
    specs = [node_spec('sensor_node', 'sensor', 1), node_spec('controller_node', 'controller', 2),
             node_spec('robot_node', 'robot', 3)]
    return json.dumps([{k: v for k, v in vars(s).items()} for s in specs])


def node_pids(launcher: psutil.Process) -> list[int]:
    return [p.pid for p in launched_nodes(launcher.pid)]


def test_ctrl_c_stops_everything_exit_zero(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    proc: Proc = start(PY, '-c', RUNNER, three_nodes_json(), '1',
                       env={'ROS_LOG_DIR': str(tmp_path)})
    proc.wait_for(r'Status: OK')
    children = node_pids(psutil.Process(proc.popen.pid))
    assert len(children) == 3
    proc.popen.send_signal(signal.SIGINT)
    assert proc.popen.wait(20) == 0
    proc.wait_for(r'sensor_node-1\]: process has finished cleanly', 5)
    out = proc.output
    assert '[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)' in out
    assert len(re.findall(r'process has (finished cleanly|died)', out)) == 3, out
    for pid in children:
        assert not psutil.pid_exists(pid)


def test_kill_9_of_launcher_leaves_no_node(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    proc: Proc = start(PY, '-c', RUNNER, three_nodes_json(), '1',
                       env={'ROS_LOG_DIR': str(tmp_path)})
    proc.wait_for(r'Status: OK')
    children = [psutil.Process(pid) for pid in node_pids(psutil.Process(proc.popen.pid))]
    assert len(children) == 3
    names = {exe for c in children for exe in ('sensor_node', 'controller_node', 'robot_node')
             if any(arg.endswith(exe) for arg in c.cmdline())}
    assert names == {'sensor_node', 'controller_node', 'robot_node'}
    os.kill(proc.popen.pid, signal.SIGKILL)
    proc.popen.wait(5)
    gone, alive = psutil.wait_procs(children, timeout=10)
    assert not alive, [p.pid for p in alive]
    assert len(gone) == 3


def test_launcher_imports_no_rclpy() -> None:
    """No DDS participant in the launcher: it must not even import rclpy."""
    code = ('import sys, robot_lab.cli.launch, robot_lab.launch.supervisor, '
            'robot_lab.launch.api; print("rclpy" in sys.modules)')
    out = subprocess.run([PY, '-c', code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == 'False'


# --- the kit's own launch files and the demo, through the real CLI ---------------------------


@pytest.mark.parametrize('file', ['robot.launch.xml', 'robot.launch.py', 'robot.launch.yaml'])
def test_kit_launch_file_runs(start, tmp_path: Path, file: str) -> None:  # type: ignore[no-untyped-def]
    proc: Proc = start('robot-lab', 'launch', 'robot_lab', file, 'robot_name:=robot_gamma',
                       env={'ROS_LOG_DIR': str(tmp_path)})
    proc.wait_for(r'^\[sensor_node-1\] .*\[sensor\]: Sensor node started \(rate: 10 Hz\)$', 20)
    proc.wait_for(r'^\[controller_node-2\] .*\[controller\]: Controller node started$', 10)
    proc.wait_for(r'^\[robot_node-3\] .*\[robot\]: Robot node started: robot_gamma$', 10)
    proc.wait_for(r'^\[robot_node-3\] .*\[robot\]: Status: OK \(temp: 2\d\.\d°C\)$', 10)
    nodes = launched_nodes(proc.popen.pid)
    assert len(nodes) == 3
    proc.popen.send_signal(signal.SIGINT)
    assert proc.popen.wait(20) == 0
    assert_all_ended(proc, nodes)


def assert_all_ended(proc: Proc, nodes: list[psutil.Process]) -> None:
    """Every node got its end line and is gone.

    Exit codes are the nodes' business: the kit's robot_node can still die with an rclpy
    RuntimeError when SIGINT lands while it takes a message (robot_lab/nodes/base.py).
    """
    ended = [ln for ln in proc.lines if re.search(r'process has (finished cleanly|died)', ln)]
    assert len(ended) == len(nodes), proc.output[-3000:]
    _gone, alive = psutil.wait_procs(nodes, timeout=5)
    assert not alive


def test_kit_robot_sim_runs_two_robots(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    from robot_lab.graph.api import wait_for_nodes

    proc: Proc = start('robot-lab', 'launch', 'robot_lab', 'robot_sim.launch.xml',
                       env={'ROS_LOG_DIR': str(tmp_path)})
    proc.wait_for(r'^\[robot_node-3\] .*\[robot1\.robot\]: Robot node started: robot_one$', 20)
    proc.wait_for(r'^\[robot_node-6\] .*\[robot2\.robot\]: Robot node started: robot_two$', 20)
    proc.wait_for(r'^\[robot_node-3\] .*\[robot1\.robot\]: Status: OK', 10)
    proc.wait_for(r'^\[robot_node-6\] .*\[robot2\.robot\]: Status: OK', 10)
    wait_for_nodes([f'/robot{n}/{node}' for n in (1, 2)
                    for node in ('sensor', 'controller', 'robot')], timeout=15)
    nodes = launched_nodes(proc.popen.pid)
    assert len(nodes) == 6
    proc.popen.send_signal(signal.SIGINT)
    assert proc.popen.wait(20) == 0
    assert_all_ended(proc, nodes)


def test_demo_runs_and_summarises(tmp_path: Path) -> None:
    from conftest import run_cli

    result = run_cli('demo', '--duration', '3', env={'ROS_LOG_DIR': str(tmp_path)}, timeout=60)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    out = result.stdout
    for pattern in (r'\[sensor\]: Sensor node started \(rate: 10 Hz\)',
                    r'\[controller\]: Controller node started',
                    r'\[robot\]: Robot node started: my_robot',
                    r'\[robot\]: Status: OK \(temp: 2\d\.\d°C\)'):
        assert re.search(pattern, out), pattern
    assert 'nodes seen: /controller, /robot, /sensor' in out
    counts = dict(re.findall(r'^  (/\S+): (\d+) messages', out, re.M))
    assert int(counts['/sensor/temperature']) > 0 and int(counts['/robot/status']) > 0
    assert len(re.findall(r'process has (finished cleanly|died)', out)) == 3


def test_show_args_print_and_errors_start_nothing(tmp_path: Path) -> None:
    from conftest import REPO, run_cli

    env = {'ROS_LOG_DIR': str(tmp_path / 'log')}
    shown = run_cli('launch', 'robot_lab', 'robot.launch.xml', '--show-args', env=env)
    assert shown.returncode == 0
    assert shown.stdout.splitlines()[:5] == [
        "Arguments (pass arguments as '<name>:=<value>'):",
        '',
        "    'robot_name':",
        '        Name the robot node reports',
        "        (default: 'my_robot')",
    ]
    printed = run_cli('launch', str(REPO / 'launch' / 'robot.launch.xml'),
                      'robot_name:=zed', '--print', env=env)
    assert printed.returncode == 0, printed.stderr
    # like ros2 launch --print: the parsed description (tests/test_launch_events.py has more)
    nodes = [ln for ln in printed.stdout.splitlines() if ' Node(' in ln]
    assert [re.search(r"executable='(\w+)'", n).group(1) for n in nodes] == [  # type: ignore[union-attr]
        'sensor_node', 'controller_node', 'robot_node']
    assert 'process started' not in printed.stdout
    for bad in (['robot_lab', 'robot.launch.xml', 'robot_name=zed'],
                ['robot_lab', 'nope.launch.xml'],
                ['no_such_package', 'robot.launch.xml']):
        result = run_cli('launch', *bad, env=env)
        assert result.returncode == 1, bad
        assert len(result.stderr.strip().splitlines()) == 1, result.stderr
        assert 'process started' not in result.stdout
    assert 'malformed launch argument' in run_cli(
        'launch', 'robot_lab', 'robot.launch.xml', 'robot_name=zed', env=env).stderr
    assert not (tmp_path / 'log').exists()


KERNEL = r"""
import os, signal, sys
import robot_lab
handle = robot_lab.launch('robot_lab', 'robot.launch.xml')
handle.wait_for(r'Status: OK', timeout=30)
print('pids', *[p.pid for p in handle.processes], flush=True)
if sys.argv[1] == 'crash':
    os.kill(os.getpid(), signal.SIGKILL)  # a kernel crash or restart
print('exiting', flush=True)  # a normal end: atexit stops the launch
"""


@pytest.mark.parametrize('how', ['crash', 'exit'])
def test_notebook_kernel_end_leaves_no_node(start, tmp_path: Path, how: str) -> None:  # type: ignore[no-untyped-def]
    kernel: Proc = start(PY, '-c', KERNEL, how, env={'ROS_LOG_DIR': str(tmp_path)})
    pids = [int(p) for p in kernel.wait_for(r'^pids ([\d ]+)$', 30).group(1).split()]
    nodes = [psutil.Process(pid) for pid in pids]
    assert len(nodes) == 3
    kernel.popen.wait(20)
    _gone, alive = psutil.wait_procs(nodes, timeout=10)
    assert not alive, [p.pid for p in alive]
    if how == 'exit':
        assert kernel.popen.returncode == 0


def test_ctrl_c_while_a_request_is_being_queued(run_plan) -> None:  # type: ignore[no-untyped-def]
    """A signal handler runs in the main thread between two bytecodes, possibly while that
    thread holds the request lock (draining, or queuing the previous Ctrl-C): the handler's
    own request must not wait for it (a plain Lock deadlocked the launcher)."""
    run = run_plan(py_spec('import time; time.sleep(60)', 1))
    run.wait_for(r'\[INFO\] \[python-1\]: process started')
    sup = run.supervisor
    queued = threading.Event()

    def nested_ctrl_c() -> None:
        with sup._requests_lock:  # as if the handler interrupted the main thread here
            sup.interrupt()
        queued.set()

    worker = threading.Thread(target=nested_ctrl_c, daemon=True)
    worker.start()
    assert queued.wait(10), 'a Ctrl-C queued while the request lock was held hangs'
    assert run.join() == 0
    assert 'user interrupted with ctrl-c (SIGINT)' in run.text
