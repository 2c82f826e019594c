"""Lab 1.3 end to end, as a student does it with the kit: pkg create, the seed's three node
files, a launch file and a (nested) parameter file, doctor, build, source, launch with
robot_name:=robot_alpha; the seed's expected lines appear from real nodes."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import psutil
import pytest
from conftest import BIN, Proc, launched_nodes, run_cli
from seeds import LAB13, LAB13_EXPECTED_LINES, nest_param_file


def _sourced_env(ws: Path) -> dict[str, str]:
    """The environment after `source install/setup.bash` in a fresh shell."""
    base = {k: v for k, v in os.environ.items() if k not in ('AMENT_PREFIX_PATH', 'PYTHONPATH')}
    base['PATH'] = f'{BIN}{os.pathsep}{base.get("PATH", "")}'
    dump = subprocess.run(['bash', '-c', 'source install/setup.bash && env -0'], cwd=ws,
                          env=base, capture_output=True, check=True, timeout=60).stdout
    return dict(item.split('=', 1) for item in dump.decode().split('\0') if '=' in item)


@pytest.fixture(scope='module')
def lab13_ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Parts 1-7 of Lab 1.3, with the kit's tools; one colcon build."""
    ws = tmp_path_factory.mktemp('robot_ws')
    (ws / 'src').mkdir()
    # Part 1 (with the dependencies Part 6.2 adds by hand).
    created = run_cli('pkg', 'create', '--build-type', 'ament_python', 'my_robot_system',
                      '--dependencies', 'rclpy', 'std_msgs', 'geometry_msgs',
                      '--description', 'Complete robot system example', '--license', 'MIT',
                      cwd=ws / 'src')
    assert created.returncode == 0, created.stderr
    pkg = ws / 'src' / 'my_robot_system'
    # Parts 2-5: the seed's three node files, launch file and parameters.
    for node in ('sensor_node', 'controller_node', 'robot_node'):
        shutil.copy(LAB13 / 'my_robot_system' / f'{node}.py', pkg / 'my_robot_system')
    (pkg / 'launch').mkdir()
    shutil.copy(LAB13 / 'launch' / 'robot.launch.xml', pkg / 'launch')
    (pkg / 'config').mkdir()
    shutil.copy(LAB13 / 'config' / 'robot_params.yaml', pkg / 'config')
    return ws


def test_doctor_guides_part_5_and_6(lab13_ws: Path) -> None:
    """Before Part 6 the kit names what is missing; after it, nothing."""
    pkg = lab13_ws / 'src' / 'my_robot_system'
    before = run_cli('doctor', str(pkg))
    assert before.returncode == 1
    assert 'launch/ is not installed: launch/robot.launch.xml' in before.stdout
    assert 'config/ is not installed: config/robot_params.yaml' in before.stdout
    assert 'Cannot have a value before ros__parameters' in before.stdout  # the flat seed file
    # Part 5 the way rcl accepts it, and Part 6.1's setup.py (data_files, console scripts).
    nest_param_file(pkg / 'config' / 'robot_params.yaml')
    shutil.copy(LAB13 / 'setup.py', pkg / 'setup.py')
    after = run_cli('doctor', str(pkg))
    assert after.returncode == 0, after.stdout
    assert 'no problems found' in after.stdout


def test_build_and_launch_with_robot_alpha(
        lab13_ws: Path, start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    ws = lab13_ws
    pkg = ws / 'src' / 'my_robot_system'
    if 'ros__parameters' not in (pkg / 'config' / 'robot_params.yaml').read_text():
        test_doctor_guides_part_5_and_6(ws)  # run alone: do Parts 5-6 first
    built = run_cli('build', cwd=ws, timeout=240)  # Part 7.1
    assert built.returncode == 0, built.stdout + built.stderr
    assert 'Finished <<< my_robot_system' in built.stdout
    env = _sourced_env(ws)
    env['ROS_LOG_DIR'] = str(tmp_path / 'ros_log')
    executables = run_cli('pkg', 'executables', 'my_robot_system', env=env)
    assert executables.stdout.splitlines() == [
        'my_robot_system controller_node', 'my_robot_system robot_node',
        'my_robot_system sensor_node',
    ]
    # Part 7.3: ros2 launch my_robot_system robot.launch.xml robot_name:=robot_alpha
    proc: Proc = start('robot-lab', 'launch', 'my_robot_system', 'robot.launch.xml',
                       'robot_name:=robot_alpha', env=env, cwd=ws)
    for pattern in LAB13_EXPECTED_LINES:
        proc.wait_for(pattern, timeout=30)
    assert not [line for line in proc.lines if 'process has died' in line], proc.output
    nodes = launched_nodes(proc.popen.pid)
    assert len(nodes) == 3
    # Ctrl-C: the seed's main() does not catch KeyboardInterrupt, so (as under the real
    # ros2 launch) the nodes end with a traceback; what matters is that none is left.
    proc.stop()
    _gone, alive = psutil.wait_procs(nodes, timeout=15)
    assert not alive, alive


def test_in_kernel_launch_and_rebuild_without_restart(
        lab13_ws: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """The notebook path: use_workspace, robot_lab.launch, edit, build(), launch again."""
    import sys

    import robot_lab
    from robot_lab.pkg import workspace

    ws = lab13_ws
    if not (ws / 'install' / 'my_robot_system').is_dir():
        test_doctor_guides_part_5_and_6(ws)
        assert robot_lab.build(ws, progress=False).ok
    for name in ('AMENT_PREFIX_PATH', 'PYTHONPATH'):
        monkeypatch.setenv(name, os.environ.get(name, ''))
    monkeypatch.setattr(sys, 'path', list(sys.path))
    monkeypatch.setattr(workspace, '_used', [])
    monkeypatch.setenv('ROS_LOG_DIR', str(tmp_path / 'ros_log'))

    robot_lab.use_workspace(ws)
    with robot_lab.launch('my_robot_system', 'robot.launch.xml', robot_name='robot_alpha') as h:
        h.wait_for(r'Robot node started: robot_alpha', timeout=30)
        h.wait_for(r'Status: OK \(temp: 2\d\.\d°C\)', timeout=30)

    node = ws / 'src' / 'my_robot_system' / 'my_robot_system' / 'robot_node.py'
    node.write_text(node.read_text().replace("f'Robot node started: {", "f'Robot node ready: {"))
    result = robot_lab.build(ws, progress=False)
    assert result.ok, str(result)
    with robot_lab.launch('my_robot_system', 'robot.launch.xml', robot_name='robot_beta') as h:
        h.wait_for(r'Robot node ready: robot_beta', timeout=30)
