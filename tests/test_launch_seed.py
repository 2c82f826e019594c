"""The course's own packages, built with colcon, under `robot-lab launch`; the notebook handle.

Lab 1.3 (`my_robot_system`) and Chapter 6 (`robot_controller`) are built once per run
(conftest `seed_workspaces`); every launch here is the real CLI or the real notebook API
starting real nodes, and every check reads real output or asks the real ROS graph.
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest
from conftest import Proc, SeedWorkspaces, launched_nodes, run_cli
from seeds import LAB13_EXPECTED_LINES


def descendants(pid: int) -> list[psutil.Process]:
    return launched_nodes(pid)


@pytest.fixture
def seed_env(seed_workspaces: SeedWorkspaces, tmp_path: Path) -> dict[str, str]:
    return {**seed_workspaces.fixed_env, 'ROS_LOG_DIR': str(tmp_path / 'log')}


def test_observer_started_first_sees_all_three_nodes(
        start, seed_env: dict[str, str]) -> None:  # type: ignore[no-untyped-def]
    """The discovery case of issue item 10 (its speed is measured in bench/bench_launch.py)."""
    from robot_lab.graph.api import node_list, wait_for_nodes

    # First in this module: the observer's participant exists before the launch, and the
    # graph holds no stale /sensor etc. (killed nodes linger until their DDS lease ends).
    assert not {'/sensor', '/controller', '/robot'} & set(node_list(timeout=1.0))
    began = time.monotonic()
    proc: Proc = start('robot-lab', 'launch', 'my_robot_system', 'robot.launch.xml', env=seed_env)
    wait_for_nodes(['/sensor', '/controller', '/robot'], timeout=15)
    print(f'observer saw all three nodes {time.monotonic() - began:.2f} s after the launch')
    proc.wait_for(r'Status: OK', timeout=10)


def test_lab13_launch_prints_the_seed_lines_and_ctrl_c_leaves_nothing(
        start, seed_env: dict[str, str]) -> None:  # type: ignore[no-untyped-def]
    proc: Proc = start('robot-lab', 'launch', 'my_robot_system', 'robot.launch.xml',
                       'robot_name:=robot_alpha', env=seed_env)
    for pattern in LAB13_EXPECTED_LINES:
        proc.wait_for(pattern, timeout=20)
    assert proc.lines[0].startswith('[INFO] [launch]: All log files can be found below ')
    nodes = descendants(proc.popen.pid)
    assert len(nodes) == 3
    proc.popen.send_signal(signal.SIGINT)
    assert proc.popen.wait(25) == 0
    proc.wait_for(r'user interrupted with ctrl-c \(SIGINT\)', 5)
    _gone, alive = psutil.wait_procs(nodes, timeout=5)
    assert not alive
    # The seed's nodes let KeyboardInterrupt escape rclpy.spin, as under ros2 launch:
    # each one ends (cleanly or with -2), none is left running.
    ended = [line for line in proc.lines
             if 'process has finished cleanly' in line or 'process has died' in line]
    assert len(ended) == 3, proc.output[-3000:]


def test_lab13_flat_yaml_refused_before_anything_starts(
        seed_workspaces: SeedWorkspaces, tmp_path: Path) -> None:
    env = {**seed_workspaces.flat_env, 'ROS_LOG_DIR': str(tmp_path / 'log')}
    result = run_cli('launch', 'my_robot_system', 'robot.launch.xml', 'robot_name:=robot_alpha',
                     env=env, timeout=30)
    assert result.returncode == 1
    error = result.stderr.strip()
    assert len(error.splitlines()) == 1, error
    assert 'robot_params.yaml' in error and 'ros__parameters' in error
    assert 'process started' not in result.stdout
    assert not (tmp_path / 'log').exists()  # not even a log directory


def test_ch6_robot_controller_gets_its_parameter_file(
        start, seed_env: dict[str, str]) -> None:  # type: ignore[no-untyped-def]
    from robot_lab.graph.api import param_get, wait_for_nodes

    proc: Proc = start('robot-lab', 'launch', 'robot_controller', 'robot_launch.py', env=seed_env)
    proc.wait_for(r'^\[controller-1\] \[INFO\] \[[\d.]+\] \[robot_controller\]: '
                  r'Robot controller started$', timeout=20)
    wait_for_nodes(['/robot_controller'], timeout=15)
    assert param_get('/robot_controller', 'max_speed') == 2.5
    assert param_get('/robot_controller', 'update_rate') == 20.0
    cmdline = descendants(proc.popen.pid)[0].cmdline()
    assert '--params-file' in cmdline
    params_file = Path(cmdline[cmdline.index('--params-file') + 1])
    assert params_file.parts[-4:] == ('share', 'robot_controller', 'config', 'params.yaml')
    assert 'install' in params_file.parts  # the colcon-installed copy, found via the index


def test_kill_9_of_cli_launcher_leaves_no_node(start, seed_env: dict[str, str]) -> None:  # type: ignore[no-untyped-def]
    proc: Proc = start('robot-lab', 'launch', 'my_robot_system', 'robot.launch.xml', env=seed_env)
    proc.wait_for(r'Status: OK', timeout=20)
    nodes = descendants(proc.popen.pid)
    assert len(nodes) == 3
    os.kill(proc.popen.pid, signal.SIGKILL)
    proc.popen.wait(5)
    _gone, alive = psutil.wait_procs(nodes, timeout=10)
    assert not alive, [p.pid for p in alive]


# --- the notebook handle ---------------------------------------------------------------------


@pytest.fixture
def notebook_env(seed_env: dict[str, str], monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    for key, value in seed_env.items():
        monkeypatch.setenv(key, value)
    yield
    from robot_lab.launch.api import running_launches

    for handle in running_launches():
        handle.shutdown()


def test_notebook_handle_processes_logs_wait_for_and_html(notebook_env: None) -> None:
    import robot_lab

    with robot_lab.launch('my_robot_system', 'robot.launch.xml', robot_name='robot_beta') as h:
        found = h.wait_for(r'Robot node started: (\w+)', timeout=20)
        assert found.group(1) == 'robot_beta'
        h.wait_for(r'Status: OK', timeout=15)
        # Status OK needs only the controller (it starts from 22.0 °C); wait for the sensor
        # too, so the log filter below is checked against a line that has really arrived.
        h.wait_for(r'Sensor node started \(rate: 10 Hz\)', timeout=15)
        procs = h.processes
        assert [(p.name, p.label, p.state) for p in procs] == [
            ('/sensor', 'sensor_node-1', 'running'),
            ('/controller', 'controller_node-2', 'running'),
            ('/robot', 'robot_node-3', 'running'),
        ]
        children = {c.pid for c in psutil.Process().children(recursive=True)}
        assert all(p.pid in children for p in procs)
        robot_lines = h.logs(node='robot')
        assert robot_lines and all('[robot_node-3]' in line for line in robot_lines)
        sensor_lines = h.logs(node='/sensor')
        assert any(ln.endswith('Sensor node started (rate: 10 Hz)') for ln in sensor_lines)
        by_executable = h.logs(node='robot_node')
        assert by_executable[:len(robot_lines)] == robot_lines
        assert all('[WARN]' in line or '[ERROR]' in line for line in h.logs(level='WARN'))
        assert any('Status: OK' in line for line in h.logs(level='INFO'))
        html = h._repr_html_()
        assert html.count('<tr>') == 4 and html.count('#2e7d32') == 3  # header + 3 green lights
        with pytest.raises(robot_lab.LaunchError, match='no output line matched'):
            h.wait_for(r'this never appears', timeout=0.5)
    assert not h.running
    # The seed's nodes end cleanly or with the SIGINT's KeyboardInterrupt traceback (they
    # do not catch it, as under ros2 launch); what matters is that none runs on.
    assert all(p.state in ('finished', 'died') and p.exit_code is not None for p in h.processes)
    for p in h.processes:
        assert p.pid is not None and not psutil.pid_exists(p.pid)


def test_notebook_rerun_replaces_the_previous_launch(notebook_env: None) -> None:
    import robot_lab

    first = robot_lab.launch('my_robot_system', 'robot.launch.xml')
    first.wait_for(r'Status: OK', timeout=20)
    first_pids = [p.pid for p in first.processes]
    second = robot_lab.launch('my_robot_system', 'robot.launch.xml')  # the cell, run again
    assert not first.running
    assert all(pid is not None and not psutil.pid_exists(pid) for pid in first_pids)
    second.wait_for(r'Status: OK', timeout=20)
    live = [c for c in psutil.Process().children(recursive=True)
            if any(a.endswith(('sensor_node', 'controller_node', 'robot_node'))
                   for a in c.cmdline())]
    assert sorted(c.pid for c in live) == sorted(p.pid for p in second.processes)
    second.shutdown()
    assert not second.running
    assert all(p.state != 'running' for p in second.processes)
