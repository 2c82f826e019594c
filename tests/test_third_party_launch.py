"""Launch files nobody here wrote (ros2/demos, ros2/launch, ros2/launch_ros, the Jazzy launch
tutorials; see tests/data/third_party_launch/README.md): `robot-lab launch --print`
describes each one without a traceback or hang, composable nodes and `python3`-only
scripts get one clear line, and what needs no missing package really runs.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import BIN, Proc

DATA = Path(__file__).parent / 'data' / 'third_party_launch'
LAUNCH_FILES = sorted(p.name for p in DATA.iterdir()
                      if p.suffix in ('.py', '.xml', '.yaml') and p.name != 'counter.py'
                      and p.name != 'turtlesim.yaml')
# Files real `ros2 launch` refuses too: main() scripts for `python3 FILE` (no
# generate_launch_description), and composable nodes (no rclcpp_components on PyPI).
REFUSED = {
    'demos__composition__composition_demo_launch.py': 'composable nodes need rclcpp_components',
    'launch__launch_counters.py': 'launch.LaunchIntrospector is not supported',
    'launch_ros__pub_sub_launch.py': 'launch.LaunchIntrospector is not supported',
    'launch_ros__lifecycle_pub_sub_launch.py': "required function 'generate_launch_description()'",
}


@pytest.fixture(scope='module')
def stand_in_prefix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The share/ files the tutorials' launch files read at description time: the
    launch_tutorial package of the large-projects tutorial, turtle_tf2_py's rviz config and
    dummy_robot_bringup's URDF. Only files: none of their executables exist here."""
    prefix = tmp_path_factory.mktemp('prefix')
    share = prefix / 'share'
    index = share / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    for package in ('launch_tutorial', 'turtle_tf2_py', 'dummy_robot_bringup'):
        (index / package).touch()
    (share / 'launch_tutorial' / 'launch').mkdir(parents=True)
    (share / 'launch_tutorial' / 'config').mkdir()
    for path in DATA.glob('docs__*'):
        shutil.copy(path, share / 'launch_tutorial' / 'launch' / path.name.removeprefix('docs__'))
    shutil.copy(DATA / 'turtlesim.yaml', share / 'launch_tutorial' / 'config')
    (share / 'turtle_tf2_py' / 'rviz').mkdir(parents=True)
    (share / 'turtle_tf2_py' / 'rviz' / 'turtle_rviz.rviz').write_text('')
    (share / 'dummy_robot_bringup' / 'launch').mkdir(parents=True)
    (share / 'dummy_robot_bringup' / 'launch' / 'single_rrbot.urdf').write_text('<robot/>\n')
    return prefix


def _print(name: str, prefix: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, AMENT_PREFIX_PATH=str(prefix))
    return subprocess.run([str(BIN / 'robot-lab'), 'launch', name, '--print'], cwd=DATA,
                          env=env, capture_output=True, text=True, timeout=60, check=False)


def test_every_file_is_described_or_refused_in_one_line(
        ros_domain: int, stand_in_prefix: Path, tmp_path: Path) -> None:
    with ThreadPoolExecutor(4) as pool:
        results = dict(zip(LAUNCH_FILES, pool.map(lambda n: _print(n, stand_in_prefix),
                                                  LAUNCH_FILES), strict=True))
    assert len(results) >= 40
    for name, result in results.items():
        shown = f'{name}: rc={result.returncode}\n{result.stdout}{result.stderr}'
        assert 'Traceback' not in result.stdout + result.stderr, shown
        if name in REFUSED:
            assert result.returncode != 0, shown
            lines = result.stderr.splitlines()
            assert len(lines) == 1 and REFUSED[name] in lines[0], shown
            assert lines[0].startswith(str(DATA / name)), shown  # names the file (and line)
        else:
            assert result.returncode == 0, shown
            assert result.stdout.startswith(f'LaunchDescription {DATA / name}\n'), shown
            assert not result.stderr, shown


def test_describe_follows_the_tutorials_packages(ros_domain: int, stand_in_prefix: Path) -> None:
    """The large-projects tutorial: includes and a parameter file found in launch_tutorial."""
    top = _print('docs__launch_turtlesim_launch.py', stand_in_prefix).stdout
    assert top.count('IncludeLaunchDescription(') == 6
    assert f"'{stand_in_prefix}/share/launch_tutorial/launch' + '/mimic_launch.py'" in top
    # each include's path is known without a launch context, so --print expands it as
    # launch's introspector does: the included file and the nodes it starts
    share = stand_in_prefix / 'share' / 'launch_tutorial' / 'launch'
    for name in ('turtlesim_world_1', 'turtlesim_world_2', 'broadcaster_listener', 'mimic',
                 'fixed_broadcaster', 'turtlesim_rviz'):
        assert f'LaunchDescription {share / name}_launch.py\n' in top, top
    assert top.count("Node(executable='turtlesim_node', package='turtlesim'") == 2, top
    assert "Node(executable='mimic', package='turtlesim', name='mimic'" in top, top
    assert "['/input/pose', '/turtle2/pose']" in top, top
    lines = top.splitlines()
    at = next(i for i, line in enumerate(lines) if line.endswith(f'{share}/mimic_launch.py'))
    assert "+ '/mimic_launch.py')" in lines[at - 1], top  # right under its include
    world2 = _print('docs__turtlesim_world_2_launch.py', stand_in_prefix).stdout
    assert f'{stand_in_prefix}/share/launch_tutorial/config/turtlesim.yaml' in world2
    assert "namespace='turtlesim2'" in world2


def test_print_leaves_an_include_that_needs_its_context(tmp_path: Path) -> None:
    """`$(dirname)` and an argument need the launch context: shown, not expanded; an
    include of the including file itself is shown once, not followed round."""
    (tmp_path / 'child.launch.xml').write_text(
        '<launch><node pkg="robot_lab" exec="sensor_node" name="child"/></launch>\n')
    (tmp_path / 'top.launch.xml').write_text(
        '<launch>\n  <arg name="which" default="child"/>\n'
        f'  <include file="{tmp_path}/child.launch.xml"/>\n'
        '  <include file="$(dirname)/child.launch.xml"/>\n'
        '  <include file="$(var which).launch.xml"/>\n'
        f'  <include file="{tmp_path}/top.launch.xml"/>\n</launch>\n')
    result = subprocess.run([str(BIN / 'robot-lab'), 'launch', str(tmp_path / 'top.launch.xml'),
                             '--print'], capture_output=True, text=True, timeout=60,
                            check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.count(f'LaunchDescription {tmp_path}/child.launch.xml') == 1
    assert result.stdout.count("name='child'") == 1, result.stdout
    assert result.stdout.count(f'LaunchDescription {tmp_path}/top.launch.xml') == 1


def test_missing_package_is_one_line_and_nothing_starts(ros_domain: int) -> None:
    """Running a tutorial file whose package is C++ (demo_nodes_cpp): one line at the
    <node>. (turtlesim was this example until the kit had one.)"""
    result = subprocess.run([str(BIN / 'robot-lab'), 'launch', 'docs__my_script_launch.xml'],
                            cwd=DATA, capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 1
    assert result.stdout == ''
    assert result.stderr.splitlines() == [
        f"{DATA / 'docs__my_script_launch.xml'}:2: Package 'demo_nodes_cpp' not found "
        + result.stderr.split("Package 'demo_nodes_cpp' not found ", 1)[1].rstrip('\n')]


def test_launch_counters_example_runs_with_its_io_handler(ros_domain: int) -> None:
    """launch's own disable_emulate_tty_counters.py: ExecuteProcess + OnProcessIO printing
    `[process_name] line` for each line the child writes, until Ctrl-C."""
    launcher = Proc([str(BIN / 'robot-lab'), 'launch', 'launch__disable_emulate_tty_counters.py'],
                    cwd=DATA, env=dict(os.environ))
    try:
        launcher.wait_for(r'^\[python-1\] Counter: 1$', timeout=30)
        launcher.wait_for(r'^\[python-1\] Counter: 2$', timeout=10)
    finally:
        launcher.stop()
    # counter.py's own KeyboardInterrupt traceback at Ctrl-C is the child's (as in ROS 2);
    # the launcher's lines must hold none, nor a handler error.
    own = [line for line in launcher.lines if not line.startswith('[python-1] ')]
    assert not [line for line in own if 'Traceback' in line or 'raised' in line], own
