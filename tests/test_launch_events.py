"""Launch constructs of the official Jazzy tutorials: event handlers, EmitEvent(Shutdown),
LogInfo, TimerAction, ExecuteProcess (shell, on_exit, respawn), GroupAction scoping,
`--print`, substitutions, SetUseSimTime, `<let>`/`<reset>`, and one clear line for
everything robot_lab cannot run. The two launches that run start real processes (one a
real node); the rest resolve files without DDS."""

from __future__ import annotations

import os
import re
import sys
import textwrap
from pathlib import Path

import pytest
import yaml

from robot_lab.errors import LaunchError
from robot_lab.launch.plan import EventHandlerSpec, LogAction, ProcessSpec
from robot_lab.launch.resolve import describe_launch

DATA = Path(__file__).resolve().parent / 'data' / 'launch' / 'events'


def write(tmp_path: Path, text: str, name: str) -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).lstrip())
    return path


def launcher_lines(text: str) -> list[str]:
    """The launcher's own lines (`[LEVEL] [name]: msg`), in order."""
    return [ln for ln in text.splitlines() if re.match(r'\[(INFO|ERROR|WARNING)\] \[', ln)]


def before(lines: list[str], first: str, second: str) -> bool:
    index = {ln: i for i, ln in reversed(list(enumerate(lines)))}
    return index[first] < index[second]


# ----------------------------------------------------------------------- running launches


def test_tutorial_event_handlers_drive_a_real_node(tmp_path: Path) -> None:
    from conftest import run_cli

    result = run_cli('launch', str(DATA / 'tutorial_events.launch.py'),
                     env={'ROS_LOG_DIR': str(tmp_path), 'TEST_USER': 'ada'}, timeout=90)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    lines = launcher_lines(result.stdout)
    started = next(ln for ln in lines if ln.startswith('[INFO] [sensor_node-1]: process started'))
    wanted = [
        '[INFO] [launch.user]: Sensor started, greeting',  # OnProcessStart
        '[INFO] [launch.user]: Greet says "spawned turtle2"',  # OnProcessIO on_stdout
        '[INFO] [launch.user]: Greet finished',  # OnExecutionComplete
        '[INFO] [launch.user]: Launch was asked to shutdown: Window closed',  # OnShutdown
        "[INFO] [sensor_node-1]: sending signal 'SIGINT' to process[sensor_node-1]",
        '[INFO] [launch.user]: ada closed the sensor',  # OnProcessExit + EnvironmentVariable
    ]
    for line in wanted:
        assert line in lines, (line, result.stdout)
    greet = next(ln for ln in lines if ln.startswith('[INFO] [greet-2]: process started'))
    assert before(lines, started, wanted[0]) and before(lines, wanted[0], greet)
    assert before(lines, wanted[1], wanted[2])
    # EmitEvent(Shutdown) came from the node's own start line, through OnProcessIO + timer
    assert '[sensor]: Sensor node started' in result.stdout
    assert before(lines, wanted[3], wanted[4]) and before(lines, wanted[4], wanted[5])
    assert '[INFO] [sensor_node-1]: process has finished cleanly' in result.stdout


def test_execute_process_shell_on_exit_respawn_and_group_scope(tmp_path: Path) -> None:
    from conftest import run_cli

    result = run_cli('launch', str(DATA / 'process_options.launch.py'),
                     env={'ROS_LOG_DIR': str(tmp_path)}, timeout=60)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    out = result.stdout
    # GroupAction scopes launch configurations and the environment; shell=True expands $VARS
    assert '[inside-1] group sees inner scoped' in out
    assert '[outside-2] outside sees outer unset' in out
    assert '[INFO] [launch.user]: outside is done' in out  # on_exit=[LogInfo(...)]
    # respawn once (max_retries=1), and on_exit=function(event, context) sees each exit
    assert len(re.findall(r'\[flaky-3\]: process started', out)) == 2
    assert out.count('[INFO] [launch.user]: flaky-3 ended with 3') == 2
    # on_exit=[Shutdown()] ends the launch; the other handlers still answer the exits
    assert "[INFO] [sleeper-4]: sending signal 'SIGINT' to process[sleeper-4]" in out
    assert '[INFO] [launch.user]: sleeper stopped' in out


# ------------------------------------------------------------------------- --print


def test_print_describes_without_evaluating_or_writing(tmp_path: Path) -> None:
    from conftest import run_cli

    marker = tmp_path / 'evaluated'
    launch = write(tmp_path, f"""
        <launch>
          <arg name="needed" description="no default: --print must not ask for it"/>
          <let name="side" value="$(command 'touch {marker}')"/>
          <node pkg="robot_lab" exec="sensor_node" name="sensor" if="$(var needed)">
            <param name="rate" value="$(var needed)"/>
            <param name="label" value="plain"/>
          </node>
          <timer period="1.0"><log message="later"/></timer>
        </launch>
        """, 'print.launch.xml')
    scratch = tmp_path / 'tmp'
    scratch.mkdir()
    result = run_cli('launch', str(launch), '--print',
                     env={'TMPDIR': str(scratch), 'ROS_LOG_DIR': str(tmp_path / 'log')})
    assert result.returncode == 0, result.stderr
    assert not marker.exists()  # $(command) was not run
    assert list(scratch.iterdir()) == []  # no parameter file written
    assert not (tmp_path / 'log').exists()
    lines = result.stdout.splitlines()
    assert lines[0] == f'LaunchDescription {launch}'
    assert any(ln.startswith("├── DeclareLaunchArgument(name='needed'") for ln in lines)
    node = next(ln for ln in lines if 'Node(' in ln)
    assert "executable='sensor_node'" in node and "LaunchConfiguration('needed')" in node
    assert "condition=IfCondition(LaunchConfiguration('needed'))" in node
    assert node.endswith('# print.launch.xml:4')
    assert "Command('touch " in result.stdout
    assert lines[-1] == "    └── LogInfo(message='later', level='INFO')  # print.launch.xml:8"


# --------------------------------------------------------- resolved without starting


def test_event_handlers_resolve_to_handler_specs_in_order(tmp_path: Path) -> None:
    plan = describe_launch(DATA / 'tutorial_events.launch.py', args={})
    kinds = [a.event for a in plan.actions if isinstance(a, EventHandlerSpec)]
    assert kinds == ['process_start', 'process_io', 'execution_complete', 'process_io',
                     'process_exit', 'shutdown']
    sensor = plan.processes()[0]
    assert all(a.matches(sensor.origin) for a in plan.actions
               if isinstance(a, EventHandlerSpec) and a.event == 'process_start')
    # a handler's actions resolve when the event comes, in the context it was registered in
    start = next(a for a in plan.actions if isinstance(a, EventHandlerSpec))
    actions = start.respond(object())
    assert isinstance(actions[0], LogAction) and actions[0].message == 'Sensor started, greeting'
    assert isinstance(actions[1], ProcessSpec) and actions[1].label == 'greet'


def test_substitutions_let_reset_and_set_use_sim_time(tmp_path: Path) -> None:
    launch = write(tmp_path, """
        <launch>
          <let name="mode" value="fast"/>
          <let name="speed" value="$(eval '2 * 21')"/>
          <log message="ne=$(not-equals $(var mode) slow) any=$(any false 0 true) \
all=$(all true 1 false)"/>
          <log message="logs in $(log_dir)"/>
          <group>
            <set_use_sim_time value="true"/>
            <node pkg="robot_lab" exec="sensor_node" name="sim_sensor"/>
          </group>
          <node pkg="robot_lab" exec="sensor_node" name="wall_sensor">
            <param name="speed" value="$(var speed)"/>
          </node>
          <reset><keep name="kept" value="$(var mode)"/></reset>
          <log message="kept=$(var kept) mode=$(var mode unset)"/>
        </launch>
        """, 'subs.launch.xml')
    plan = describe_launch(launch, args={})
    messages = [a.message for a in plan.actions if isinstance(a, LogAction)]
    assert messages[0] == 'ne=true any=true all=false'
    assert plan.log_dir is not None and messages[1] == f'logs in {plan.log_dir}'
    assert plan.log_dir.is_dir()
    assert messages[2] == 'kept=fast mode=unset'
    sim, wall = plan.processes()
    assert '-p' in sim.cmd and 'use_sim_time:=True' in sim.cmd  # scoped to the group
    assert 'use_sim_time:=True' not in wall.cmd
    files = [wall.cmd[i + 1] for i, part in enumerate(wall.cmd) if part == '--params-file']
    assert yaml.safe_load(Path(files[0]).read_text())['/**']['ros__parameters'] == {
        'speed': 42}


def test_python_substitutions_and_find_package_share(tmp_path: Path) -> None:
    launch = write(tmp_path, """
        from launch import LaunchDescription
        from launch.actions import LogInfo, SetLaunchConfiguration
        from launch.substitutions import (
            AllSubstitution, AnySubstitution, LaunchConfiguration, LaunchLogDir,
            NotEqualsSubstitution, PythonExpression)
        from launch_ros.actions import SetUseSimTime
        from launch_ros.substitutions import FindPackageShare


        def generate_launch_description():
            share = FindPackageShare('robot_lab').find('robot_lab')
            return LaunchDescription([
                SetLaunchConfiguration('n', '3'),
                LogInfo(msg=['share=', share]),
                LogInfo(msg=PythonExpression([LaunchConfiguration('n'), ' * 2'])),
                LogInfo(msg=[NotEqualsSubstitution('a', 'b'), AnySubstitution('0', 'false'),
                             AllSubstitution('1', 'true')]),
                LogInfo(msg=LaunchLogDir()),
                SetUseSimTime(True),
            ])
        """, 'subs.launch.py')
    plan = describe_launch(launch, args={})
    messages = [a.message for a in plan.actions if isinstance(a, LogAction)]
    from robot_lab.pkg.index import package_share

    assert messages[:3] == [f'share={package_share("robot_lab")}', '6', 'truefalsetrue']
    assert messages[3] == str(plan.log_dir)


# ------------------------------------------------------------------- one clear line


@pytest.mark.parametrize(('name', 'text', 'line', 'says'), [
    ('container.launch.xml', """
        <launch>
          <node_container pkg="rclcpp_components" exec="component_container" name="c"
                          namespace="">
            <composable_node pkg="composition" plugin="composition::Talker" name="talker"/>
          </node_container>
        </launch>
        """, 2, 'composable nodes are not supported'),
    ('container.launch.py', """
        from launch import LaunchDescription
        from launch_ros.actions import ComposableNodeContainer


        def generate_launch_description():
            return LaunchDescription([])
        """, 2, 'launch_ros.actions.ComposableNodeContainer is not supported'),
    ('coroutine.launch.py', """
        import launch
        from launch.actions import OpaqueCoroutine


        def generate_launch_description():
            return launch.LaunchDescription([])
        """, 2, 'launch.actions.OpaqueCoroutine is not supported'),
    ('logging.launch.py', """
        import launch
        import launch.logging


        def generate_launch_description():
            return launch.LaunchDescription([])
        """, 2, "launch.logging is not provided by robot_lab's launcher"),
    ('param.launch.xml', """
        <launch>
          <node pkg="robot_lab" exec="sensor_node" name="sensor">
            <param name="rate" value="10.0"/>
            <param name="label" value="$(env ROBOT_LAB_SURELY_UNSET_VAR)"/>
          </node>
        </launch>
        """, 4, "environment variable 'ROBOT_LAB_SURELY_UNSET_VAR' does not exist"),
    ('optenv.launch.xml', """
        <launch>
          <node pkg="robot_lab" exec="sensor_node" name="sensor">
            <param name="label" value="$(optenv ROBOT_LAB_SURELY_UNSET_VAR)"/>
          </node>
        </launch>
        """, 3, 'Unknown substitution: optenv'),
    ('local.launch.py', """
        from launch import LaunchDescription
        from launch.actions import LogInfo
        from launch.substitutions import LocalSubstitution


        def generate_launch_description():
            return LaunchDescription([LogInfo(msg=LocalSubstitution('event.reason'))])
        """, 7, "'event' is not in the context's locals"),
])
def test_unsupported_or_wrong_is_one_line_at_its_line(
        tmp_path: Path, name: str, text: str, line: int, says: str) -> None:
    path = write(tmp_path, text, name)
    with pytest.raises(LaunchError) as info:
        describe_launch(path, args={})
    err = info.value
    assert (Path(str(err.file)), err.line) == (path, line), str(err)
    assert says in err.message
    if 'composable' in says.lower() or 'Composable' in says:
        assert err.fix is not None and 'own Node(' in err.fix


def test_unsupported_construct_cli_starts_nothing(tmp_path: Path) -> None:
    from conftest import run_cli

    path = write(tmp_path, """
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess, OpaqueCoroutine


        def generate_launch_description():
            return LaunchDescription([ExecuteProcess(cmd=['sleep', '30'])])
        """, 'bad.launch.py')
    result = run_cli('launch', str(path), env={'ROS_LOG_DIR': str(tmp_path / 'log')})
    assert result.returncode == 1
    assert result.stderr.strip().count('\n') == 0, result.stderr
    assert f'{path}:2: launch.actions.OpaqueCoroutine is not supported' in result.stderr
    assert 'Traceback' not in result.stderr and 'process started' not in result.stdout


def test_facade_exports_what_tutorials_and_demos_import() -> None:
    """Names the Jazzy tutorials and ros2/demos launch files import, all importable."""
    code = textwrap.dedent("""
        from robot_lab.launch.compat_path import compat_api
        with compat_api():
            import launch, launch_ros
            from launch import LaunchContext, LaunchDescription, Substitution
            from launch.actions import (
                DeclareLaunchArgument, EmitEvent, ExecuteProcess, GroupAction,
                IncludeLaunchDescription, LogInfo, OpaqueFunction, RegisterEventHandler,
                SetEnvironmentVariable, SetLaunchConfiguration, Shutdown, TimerAction)
            from launch.conditions import IfCondition, UnlessCondition
            from launch.event_handlers import (
                OnExecutionComplete, OnProcessExit, OnProcessIO, OnProcessStart, OnShutdown)
            from launch.events import Shutdown as ShutdownEvent
            from launch.events.process import ProcessExited, ProcessIO, ProcessStarted
            from launch.launch_description_sources import PythonLaunchDescriptionSource
            from launch.substitutions import (
                Command, EnvironmentVariable, FindExecutable, LaunchConfiguration,
                LocalSubstitution, PathJoinSubstitution, PythonExpression,
                TextSubstitution, ThisLaunchFileDir)
            from launch_ros.actions import Node, PushRosNamespace, SetParameter, SetUseSimTime
            from launch_ros.actions import LifecycleNode
            from launch_ros.event_handlers import OnStateTransition
            from launch_ros.events.lifecycle import ChangeState
            from launch.events import matches_action
            from launch_ros.parameter_descriptions import ParameterValue
            from launch_ros.substitutions import FindPackageShare
            from launch_xml.launch_description_sources import XMLLaunchDescriptionSource
            from launch_yaml.launch_description_sources import YAMLLaunchDescriptionSource
            print('ok')
    """)
    import subprocess

    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            timeout=60, env=dict(os.environ), check=False)
    assert result.stdout.strip() == 'ok', result.stderr
