"""`robot-lab node/topic/param/service/interface` against the real three-node system.

Each command is a cold process, as a student types it: it must wait out discovery itself
and print what ros2cli prints.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import BIN, Proc, cli_ok, reference_system, run_cli
from rosutil import check_ten_hertz, last_hz_window

from robot_lab.params import load_param_file


@pytest.fixture(scope='module')
def system(ros_domain: int) -> Iterator[dict[str, Proc]]:
    """/sensor, /controller, /robot as the launch file names them, for the whole module."""
    with reference_system() as procs:
        yield procs


def test_node_list_prints_exactly_the_three_nodes(system: dict[str, Proc]) -> None:
    assert cli_ok('node', 'list') == '/controller\n/robot\n/sensor\n'


def test_node_list_all_shows_hidden_nodes_too(system: dict[str, Proc]) -> None:
    lines = cli_ok('node', 'list', '--all').splitlines()
    assert {'/controller', '/robot', '/sensor'} <= set(lines)
    assert any(line.startswith('/_robot_lab_') for line in lines)  # the CLI's own session


def test_node_info_layout(system: dict[str, Proc]) -> None:
    out = cli_ok('node', 'info', '/controller')
    assert out.startswith(
        '/controller\n'
        '  Subscribers:\n'
        '    /sensor/temperature: std_msgs/msg/Float32\n'
        '  Publishers:\n'
        '    /cmd_vel: geometry_msgs/msg/Twist\n'
        '    /parameter_events: rcl_interfaces/msg/ParameterEvent\n'
        '    /robot/status: std_msgs/msg/String\n'
        '    /rosout: rcl_interfaces/msg/Log\n'
        '  Service Servers:\n'
        '    /controller/describe_parameters: rcl_interfaces/srv/DescribeParameters\n'
    )
    assert out.endswith('  Service Clients:\n\n  Action Servers:\n\n  Action Clients:\n\n')


def test_unknown_node(system: dict[str, Proc]) -> None:
    result = run_cli('node', 'info', '/nope')
    assert result.returncode == 1
    assert "Unable to find node '/nope'" in result.stderr
    assert 'robot-lab node list' in result.stderr


def test_topic_list_with_types(system: dict[str, Proc]) -> None:
    lines = cli_ok('topic', 'list', '-t').splitlines()
    for expected in ('/sensor/temperature [std_msgs/msg/Float32]',
                     '/robot/status [std_msgs/msg/String]',
                     '/cmd_vel [geometry_msgs/msg/Twist]'):
        assert expected in lines
    assert lines == sorted(lines)


def test_topic_info_and_type(system: dict[str, Proc]) -> None:
    assert cli_ok('topic', 'info', '/sensor/temperature') == (
        'Type: std_msgs/msg/Float32\nPublisher count: 1\nSubscription count: 1\n'
    )
    verbose = cli_ok('topic', 'info', '-v', '/robot/status')
    assert 'Node name: controller\nNode namespace: /\nTopic type: std_msgs/msg/String\n' in verbose
    assert 'Endpoint type: PUBLISHER' in verbose and 'Reliability: RELIABLE' in verbose
    assert cli_ok('topic', 'type', '/cmd_vel') == 'geometry_msgs/msg/Twist\n'


def test_param_get(system: dict[str, Proc]) -> None:
    assert cli_ok('param', 'get', '/sensor', 'sensor_rate') == 'Integer value is: 10\n'
    assert cli_ok('param', 'get', '/robot', 'robot_name') == 'String value is: my_robot\n'
    assert cli_ok('param', 'get', '/sensor', 'use_sim_time') == 'Boolean value is: False\n'


def test_param_list(system: dict[str, Proc]) -> None:
    out = cli_ok('param', 'list')
    assert '/sensor:\n  noise_level\n  sensor_rate\n' in out
    assert out.index('/controller:') < out.index('/robot:') < out.index('/sensor:')
    assert cli_ok('param', 'list', '/robot') == (
        '  robot_name\n  start_type_description_service\n  use_sim_time\n'
    )
    # Hidden nodes too: the kit's own (the daemon's, this command's) have no parameter
    # services, which ros2param reports on a line of their own and goes on.
    every = cli_ok('param', 'list', '--include-hidden-nodes')
    assert re.search(r'^Wait for service timed out waiting for parameter services for node '
                     r'/_robot_lab_\d+_\d+$', every, re.M), every
    assert re.sub(r'(?m)^Wait for.*\n', '', every) == out
    assert '_robot_lab_' not in out
    assert cli_ok('param', 'list', '--no-daemon') == out


def test_the_daemon_answers_the_param_verbs_as_the_node_itself_does(
        system: dict[str, Proc], tmp_path: Path) -> None:
    """Beyond ros2cli, a running daemon answers the param verbs from its warm session: each
    prints, on both streams, with the exit code, what the command prints asking the node
    itself (ROBOT_LAB_NO_DAEMON=1), and the daemon counts the answers it gave."""
    from robot_lab.graph.daemon import query, stop

    assert run_cli('daemon', 'start').returncode == 0
    try:
        values = tmp_path / 'values.yaml'
        values.write_text('/sensor:\n  ros__parameters:\n    noise_level: 0.1\n    nope: 1\n')
        commands = [
            ('param', 'get', '/sensor', 'sensor_rate'), ('param', 'get', '/robot', 'robot_name'),
            ('param', 'get', '/nobody', 'x'), ('param', 'list', '/controller'),
            ('param', 'list', '--param-type', '/robot'), ('param', 'list'),
            ('param', 'describe', '/sensor', 'noise_level', 'sensor_rate'),
            ('param', 'dump', '/robot'), ('param', 'set', '/sensor', 'noise_level', '0.1'),
            ('param', 'set', '/sensor', 'sensor_rate', 'fast'),
            ('param', 'load', '/sensor', str(values)),
            ('param', 'delete', '/sensor', 'noise_level'),
        ]
        before = query('ping')['answered']
        for args in commands:
            by_daemon = run_cli(*args)
            by_node = run_cli(*args, env={'ROBOT_LAB_NO_DAEMON': '1'})
            assert (by_daemon.returncode, by_daemon.stdout, by_daemon.stderr) == \
                (by_node.returncode, by_node.stdout, by_node.stderr), args
        after = query('ping')['answered']
        for op, times in (('param_get', 3), ('param_list', 3), ('param_describe', 5),
                          ('param_dump', 1), ('param_set', 2), ('param_load', 1),
                          ('param_delete', 1)):
            assert after.get(op, 0) - before.get(op, 0) == times, (op, before, after)
    finally:
        stop()  # the suite starts no daemon that outlives its test


def test_param_set_noise_then_echo_shows_base_temperature(system: dict[str, Proc]) -> None:
    try:
        assert cli_ok('param', 'set', '/sensor', 'noise_level', '0.0') == \
            'Set parameter successful\n'
        assert cli_ok('topic', 'echo', '/sensor/temperature', '--once') == 'data: 22.5\n---\n'
    finally:
        cli_ok('param', 'set', '/sensor', 'noise_level', '0.1')


def test_threshold_flips_status_to_high_and_stops_the_robot(system: dict[str, Proc]) -> None:
    cli_ok('param', 'set', '/sensor', 'noise_level', '0.0')
    try:
        assert cli_ok('param', 'set', '/controller', 'temp_threshold', '20.0') == (
            'Set parameter successful\n'
        )
        status = cli_ok('topic', 'echo', '/robot/status', '--times', '3', '--field', 'data')
        assert status.splitlines()[-2] == 'HIGH (temp: 22.5°C)'
        speed = cli_ok('topic', 'echo', '/cmd_vel', '-n', '3', '--field', 'linear.x')
        assert speed.splitlines()[-2] == '0.0'
        system['controller'].wait_for(r'Temperature HIGH: 22\.50°C', timeout=5)
    finally:
        cli_ok('param', 'set', '/controller', 'temp_threshold', '25.0')
        cli_ok('param', 'set', '/sensor', 'noise_level', '0.1')
    status = cli_ok('topic', 'echo', '/robot/status', '--times', '3', '--field', 'data')
    assert status.splitlines()[-2].startswith('OK (temp: ')


def test_wrong_type_is_refused_and_node_keeps_publishing(system: dict[str, Proc]) -> None:
    result = run_cli('param', 'set', '/sensor', 'noise_level', 'abc')
    assert result.stderr == (
        "Setting parameter failed: Wrong parameter type, expected 'Type.DOUBLE' "
        "got 'Type.STRING'\n"
    )
    assert system['sensor'].popen.poll() is None
    assert cli_ok('param', 'get', '/sensor', 'noise_level') == 'Double value is: 0.1\n'
    assert cli_ok('topic', 'echo', '/sensor/temperature', '--once').startswith('data: 2')


def test_out_of_range_is_refused_with_the_range(system: dict[str, Proc]) -> None:
    result = run_cli('param', 'set', '/sensor', 'noise_level', '9.0')
    assert result.stderr.startswith('Setting parameter failed: ')
    assert 'Min: 0.0, Max: 5.0' in result.stderr
    result = run_cli('param', 'set', '/sensor', 'sensor_rate', '500')
    assert 'Setting parameter failed: ' in result.stderr and 'Max: 100' in result.stderr
    assert cli_ok('param', 'get', '/sensor', 'sensor_rate') == 'Integer value is: 10\n'


DYNAMIC_NODE = """
import rclpy
from rcl_interfaces.msg import ParameterDescriptor
rclpy.init()
node = rclpy.create_node('scratch')
node.declare_parameter('gain', 2.5, ParameterDescriptor(dynamic_typing=True))
print('up', flush=True)
rclpy.spin(node)
"""


def test_param_delete_as_ros2param(system: dict[str, Proc], start) -> None:  # type: ignore[no-untyped-def]
    """`param delete` sets PARAMETER_NOT_SET; the node decides, as with ros2param."""
    result = run_cli('param', 'delete', '/sensor', 'noise_level')  # statically typed
    assert result.returncode == 0 and result.stdout == ''
    assert result.stderr.startswith('Deleting parameter failed: '), result.stderr
    assert cli_ok('param', 'get', '/sensor', 'noise_level') == 'Double value is: 0.1\n'
    scratch = start(str(BIN / 'python'), '-c', DYNAMIC_NODE)
    scratch.wait_for('^up$')
    assert cli_ok('param', 'get', '/scratch', 'gain') == 'Double value is: 2.5\n'
    assert cli_ok('param', 'delete', '/scratch', 'gain') == 'Deleted parameter successfully\n'
    assert 'gain' not in cli_ok('param', 'list', '/scratch').split()


def test_param_get_of_a_parameter_the_node_lacks(system: dict[str, Proc], start) -> None:  # type: ignore[no-untyped-def]
    """ros2param's two answers: an rclpy node returns no value (an error, exit 1); a node
    that allows undeclared parameters returns PARAMETER_NOT_SET (a line, exit 0)."""
    result = run_cli('param', 'get', '/sensor', 'no_such')
    assert result.returncode == 1 and result.stdout == ''
    assert result.stderr.startswith("Parameter not set: 'no_such' on /sensor"), result.stderr
    assert 'param list /sensor' in result.stderr
    scratch = start(str(BIN / 'python'), '-c', DYNAMIC_NODE.replace(
        "'scratch'", "'open', allow_undeclared_parameters=True"))
    scratch.wait_for('^up$')
    result = run_cli('param', 'get', '/open', 'no_such')
    assert (result.returncode, result.stdout) == (0, 'Parameter not set.\n'), result
    assert cli_ok('param', 'get', '/open', 'gain') == 'Double value is: 2.5\n'


def test_param_describe_layout(system: dict[str, Proc]) -> None:
    assert cli_ok('param', 'describe', '/sensor', 'sensor_rate') == (
        'Parameter name: sensor_rate\n'
        '  Type: integer\n'
        '  Description: Publish rate of /sensor/temperature in Hz\n'
        '  Constraints:\n'
        '    Min value: 1\n'
        '    Max value: 100\n'
        '    Step: 1\n'
    )


def test_param_dump_loads_back(system: dict[str, Proc], tmp_path: Path) -> None:
    out = cli_ok('param', 'dump', '/controller')
    assert out.startswith('/controller:\n  ros__parameters:\n    control_rate: 20\n')
    dumped = tmp_path / 'controller.yaml'
    dumped.write_text(out)
    params = load_param_file(dumped)['/controller']
    assert params['temp_threshold'] == 25.0 and params['max_speed'] == 0.5
    # edit the file and load it into the running node
    dumped.write_text(out.replace('max_speed: 0.5', 'max_speed: 1.5'))
    try:
        result = run_cli('param', 'load', '/controller', str(dumped))
        assert 'Set parameter max_speed successful' in result.stdout
        speed = cli_ok('topic', 'echo', '/cmd_vel', '-n', '3', '--field', 'linear.x')
        assert speed.splitlines()[-2] == '1.5'
    finally:
        cli_ok('param', 'set', '/controller', 'max_speed', '0.5')


def test_topic_hz_reports_ten_hertz(system: dict[str, Proc]) -> None:
    out = cli_ok('topic', 'hz', '/sensor/temperature', '--window', '20', '--duration', '4')
    rate, shortest, longest, size = last_hz_window(out)
    check_ten_hertz(rate, shortest, longest)
    assert size == 20, out


def test_topic_pub_reaches_a_subscriber(system: dict[str, Proc]) -> None:
    listener = Proc([str(BIN / 'robot-lab'), 'topic', 'echo', '/chatter',
                     'std_msgs/msg/String', '--once'], env=dict(os.environ))
    try:
        # With no publisher yet, echo subscribes best-effort (as ros2cli does), and the
        # publisher can match the echo's reader before that reader has matched it: a single
        # message may be lost (real ros2 too), so send a few.
        out = cli_ok('topic', 'pub', '/chatter', 'std_msgs/msg/String', '{data: hi}',
                 '--times', '20', '--rate', '10')
        assert 'publisher: beginning loop\n' in out
        assert "publishing #1: std_msgs.msg.String(data='hi')\n\n" in out
        listener.wait_for(r'^data: hi$', timeout=10)
    finally:
        listener.stop()


def test_topic_pub_errors(system: dict[str, Proc]) -> None:
    bad_type = run_cli('topic', 'pub', '/x', 'std_msgs/msg/Nope', '{data: 1}', '--once')
    assert bad_type.returncode == 1 and "'std_msgs/msg/Nope' is invalid" in bad_type.stderr
    bad_yaml = run_cli('topic', 'pub', '/x', 'std_msgs/msg/String', '{data: [', '--once')
    assert bad_yaml.returncode == 1
    assert 'needs to be a dictionary in YAML format' in bad_yaml.stderr


def test_echo_unknown_topic(system: dict[str, Proc]) -> None:
    result = run_cli('topic', 'echo', '/nope', '--once')
    assert result.returncode == 1
    assert result.stdout == 'WARNING: topic [/nope] does not appear to be published yet\n'
    assert 'Could not determine the type for the passed topic' in result.stderr


def test_service_list_and_interface_show(system: dict[str, Proc]) -> None:
    services = cli_ok('service', 'list', '-t').splitlines()
    assert '/sensor/set_parameters [rcl_interfaces/srv/SetParameters]' in services
    assert cli_ok('interface', 'show', 'geometry_msgs/msg/Twist', '--no-comments') == (
        'Vector3  linear\n\tfloat64 x\n\tfloat64 y\n\tfloat64 z\n'
        'Vector3  angular\n\tfloat64 x\n\tfloat64 y\n\tfloat64 z\n'
    )


def test_ros2_alias_prints_the_same(system: dict[str, Proc]) -> None:
    import subprocess

    out = subprocess.run([str(BIN / 'ros2'), 'node', 'list'], capture_output=True, text=True,
                         timeout=60, check=False)
    assert out.stdout == '/controller\n/robot\n/sensor\n'
