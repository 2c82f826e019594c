"""The tf2 Python tutorials as a student does them, against the kit's turtlesim.

The student's files (tests/data/tf2_tutorial_pages/: the pages' downloads and what they type)
go into a `ros2 pkg create` package, unchanged, built with colcon: the static broadcaster,
the broadcaster and listener (turtle2 follows), adding a frame (fixed and dynamic carrot1),
and traveling in time (`lookup_transform_full` 5 s in the past). The kit's own
turtle_tf2_py is not used here: these are the pages' files.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
from pathlib import Path

import pytest
from conftest import Proc, venv_env

PAGES = Path(__file__).parent / 'data' / 'tf2_tutorial_pages'
NODES = ('static_turtle_tf2_broadcaster', 'turtle_tf2_broadcaster', 'turtle_tf2_listener',
         'fixed_frame_tf2_broadcaster', 'dynamic_frame_tf2_broadcaster')
NUMBER = r'(-?\d+\.\d+)'
TRANSLATION = rf'^- Translation: \[{NUMBER}, {NUMBER}, {NUMBER}\]$'
# turtlesim's first turtle starts at the window's centre; carrot1 is 2 m to its left
CARROT_IN_WORLD = (5.544445, 7.544445)


def _run(command: str, cwd: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(['bash', '-c', command], cwd=cwd, env=venv_env(), text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True)  # its own group: colcon's children too


def _finish(proc: subprocess.Popen[str], timeout: float = 300) -> None:
    out, _ = proc.communicate(timeout=timeout)
    assert proc.returncode == 0, out


def _hand_in(ws: Path, listener: Path) -> subprocess.Popen[str]:
    """The student's learning_tf2_py in `ws`, as the pages build it; returns its colcon build.

    `ros2 pkg create`, the five downloads (with `listener` as turtle_tf2_listener.py), the
    launch files typed from the pages, and the lines the pages add to package.xml and setup.py.
    """
    (ws / 'src').mkdir(parents=True)
    created = subprocess.run(
        ['bash', '-c', 'ros2 pkg create --build-type ament_python --license Apache-2.0 -- '
         'learning_tf2_py'], cwd=ws / 'src', env=venv_env(), capture_output=True, text=True,
        timeout=120, check=False)
    assert created.returncode == 0, created.stdout + created.stderr
    pkg = ws / 'src' / 'learning_tf2_py'
    for name in NODES:
        shutil.copy(PAGES / 'downloads' / f'{name}.py', pkg / 'learning_tf2_py')
    shutil.copy(listener, pkg / 'learning_tf2_py' / 'turtle_tf2_listener.py')
    shutil.copytree(PAGES / 'typed' / 'launch', pkg / 'launch')
    typed = PAGES / 'typed'
    depends = ''.join(f'  {line}\n' for line in
                      (typed / 'package.xml.exec_depends').read_text().splitlines())
    xml = (pkg / 'package.xml').read_text()
    assert '  <test_depend>' in xml
    (pkg / 'package.xml').write_text(xml.replace('  <test_depend>', depends + '  <test_depend>',
                                                 1))
    setup = (pkg / 'setup.py').read_text()
    scripts, data_files = "        'console_scripts': [\n", '    data_files=[\n'
    assert scripts in setup and data_files in setup, setup
    setup = setup.replace(scripts, scripts + ''.join(
        f'            {line}\n'
        for line in (typed / 'setup.py.console_scripts').read_text().splitlines()), 1)
    setup = setup.replace(data_files, data_files + ''.join(
        f'        {line}\n' for line in (typed / 'setup.py.data_files').read_text().splitlines()),
        1)
    (pkg / 'setup.py').write_text((typed / 'setup.py.imports').read_text() + setup)
    return _run('colcon build --packages-select learning_tf2_py', ws)


def _translations(echo: Proc, timeout: float) -> tuple[float, float, float]:
    found = echo.wait_for(TRANSLATION, timeout=timeout)
    return float(found[1]), float(found[2]), float(found[3])


def test_tf2_tutorials_from_a_students_colcon_package(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """Static broadcaster seen by tf2_echo; turtle2 reaching carrot1 (fixed); carrot1 hopping
    round turtle1 (dynamic); and, with the time-travel listener, lookups of carrot1 5 s ago
    that fail until 5 s of history exist, then turtle2 reaching the carrot."""
    ws, ws_travel = tmp_path / 'ws', tmp_path / 'ws_travel'
    building = _hand_in(ws, PAGES / 'downloads' / 'turtle_tf2_listener.py')
    building_travel = _hand_in(ws_travel, PAGES / 'typed' / 'time_travel' /
                               'turtle_tf2_listener.py')
    try:
        _finish(building)
        _run_the_pages(start, ws, ws_travel, building_travel)
    finally:
        if building_travel.poll() is None:  # a failure before it was waited for
            os.killpg(building_travel.pid, signal.SIGKILL)
            building_travel.communicate()


def _run_the_pages(start, ws: Path, ws_travel: Path,  # type: ignore[no-untyped-def]
                   building_travel: subprocess.Popen[str]) -> None:
    """The pages' commands in order, the second build joined before the time-travel run."""

    def sourced(command: str, where: Path = ws) -> Proc:
        return start('bash', '-c', f'source install/setup.bash && exec {command}',
                     env=venv_env(), cwd=where)

    # Writing a static broadcaster
    sourced('ros2 run learning_tf2_py static_turtle_tf2_broadcaster mystaticturtle 0 0 1 0 0 0')
    static = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'world', 'mystaticturtle')
    assert _translations(static, 20) == (0.0, 0.0, 1.0)
    static.stop()

    # Adding a frame: the fixed carrot1, the listener told to follow it from the command line
    launch = sourced('ros2 launch learning_tf2_py turtle_tf2_fixed_frame_demo_launch.py '
                     'target_frame:=carrot1')
    launch.wait_for(r'Successfully spawned turtle2', timeout=30)
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'turtle2', 'carrot1', '5')
    # carrot1 seen from turtle2 comes within 0.3 m (it started 5.6 m away)
    echo.wait_for(r'^- Translation: \[-?0\.[0-2]\d\d, -?0\.[0-2]\d\d, 0\.000\]$', timeout=40)
    pose = start('ros2', 'topic', 'echo', '--once', '/turtle2/pose')
    assert float(pose.wait_for(r'^y: (\S+)$')[1]) == pytest.approx(CARROT_IN_WORLD[1], abs=0.35)
    echo.stop()
    launch.stop()

    # Adding a frame: the dynamic carrot1, 10 m from turtle1 at pi x (whole seconds) rad
    _finish(building_travel)
    launch = sourced('ros2 launch learning_tf2_py turtle_tf2_dynamic_frame_demo_launch.py')
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'turtle1', 'carrot1', '10')
    for y in ('10', '-10'):  # it hops from one side of turtle1 to the other each second
        echo.wait_for(rf'^- Translation: \[-?0\.000, {y}\.000, 0\.000\]$', timeout=20)
    echo.stop()
    launch.stop()

    # Traveling in time: carrot1 five seconds ago, turtle2 now, through the fixed `world`
    launch = sourced('ros2 launch learning_tf2_py turtle_tf2_fixed_frame_demo_launch.py '
                     'target_frame:=carrot1', where=ws_travel)
    past = launch.wait_for(
        r'Could not transform turtle2 to carrot1: Lookup would require extrapolation into the '
        r'past\.  Requested time (\d+\.\d+) but the earliest data is at time (\d+\.\d+), when '
        r'looking up transform from frame \[carrot1\] to frame \[world\]', timeout=30)
    assert 0.0 < float(past[2]) - float(past[1]) <= 5.0  # 5 s back: before the tree began
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'turtle2', 'carrot1', '5')
    # then the lookups succeed and turtle2 heads for the carrot: from 5.6 m to under 2.9 m
    echo.wait_for(r'^- Translation: \[-?[0-1]\.\d{3}, -?[0-1]\.\d{3}, 0\.000\]$', timeout=40)
    failures = [line for line in launch.lines if 'Could not transform' in line]
    # before then: too far back, or (as the nodes start) frames not yet heard of or joined
    assert all(re.search(r'extrapolation into the past|does not exist|not part of the same tree',
                         line) for line in failures), failures
