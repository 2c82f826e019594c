"""The command lines of the official ROS 2 Jazzy beginner CLI tutorials, replayed on a kit
system, print what ros2cli prints (format, not timing).

Most commands run on the kit's own nodes as stand-ins (/sensor, /controller and /robot for
the topics and parameters, /switch for services, /fibonacci_action_server for actions);
the last tests run the services, parameters and actions tutorials on the kit's turtlesim,
exactly as the pages write them. The expected texts
are ros2cli's (ros2topic, ros2service, ros2action, ros2param, ros2node, ros2interface,
ros2doctor on the jazzy branch) and rosbag2's. One system serves every test; commands that
only wait for discovery run in parallel.
"""

from __future__ import annotations

import os
import re
import subprocess
import threading
import time
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import BIN, Proc, reference_system

import robot_lab

TWIST = '{linear: {x: 2.0, y: 0.0, z: 0.0}, angular: {x: 0.0, y: 0.0, z: 1.8}}'
TWIST_REPR = ('geometry_msgs.msg.Twist(linear=geometry_msgs.msg.Vector3(x=2.0, y=0.0, z=0.0), '
              'angular=geometry_msgs.msg.Vector3(x=0.0, y=0.0, z=1.8))')


def ros2(*args: str, cwd: Path | None = None,
         timeout: float = 150) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(BIN / 'ros2'), *args], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd, env=dict(os.environ), check=False)


def ok(*args: str, cwd: Path | None = None) -> str:
    result = ros2(*args, cwd=cwd)
    assert result.returncode == 0, f'ros2 {" ".join(args)}:\n{result.stdout}{result.stderr}'
    assert 'Traceback' not in result.stderr, result.stderr
    return result.stdout


def ok_all(*commands: Sequence[str]) -> list[str]:
    with ThreadPoolExecutor(len(commands)) as pool:
        return list(pool.map(lambda args: ok(*args), commands))


@pytest.fixture(scope='module')
def system(ros_domain: int) -> Iterator[dict[str, Proc]]:
    run = [str(BIN / 'ros2'), 'run', 'robot_lab']
    extra = {
        # the services tutorial's introspection_service
        'switch': Proc([*run, 'switch_node', '--ros-args', '-p',
                        'service_configure_introspection:=contents']),
        # 0.3 s a step: the goal's feedback must lead its result by more than a late
        # delivery can take (see test_actions_tutorial)
        'fibonacci': Proc([*run, 'fibonacci_node', '--ros-args', '-p', 'step_period:=0.3']),
        # the nodes tutorial's
        # `ros2 run turtlesim turtlesim_node --ros-args --remap __node:=my_turtle`
        'my_sensor': Proc([*run, 'sensor_node', '--ros-args', '--remap', '__node:=my_sensor',
                           '-p', 'sensor_rate:=5']),
    }
    try:
        with reference_system() as reference:
            extra['switch'].wait_for('Switch node started', timeout=60)
            extra['fibonacci'].wait_for('Fibonacci action server started', timeout=60)
            extra['my_sensor'].wait_for('Sensor node started', timeout=60)
            robot_lab.wait_for_nodes(['/sensor', '/controller', '/robot', '/switch',
                                      '/fibonacci_action_server', '/my_sensor'], timeout=20)
            yield {**reference, **extra}
    finally:
        for proc in extra.values():
            proc.stop()


# Every command that only reads the graph, run at once (each mostly waits for discovery).
BATCH: dict[str, tuple[str, ...]] = {
    'executables': ('pkg', 'executables', 'robot_lab'),
    'node list': ('node', 'list'),
    'node info': ('node', 'info', '/my_sensor'),
    'topic list': ('topic', 'list'),
    'topic list -t': ('topic', 'list', '-t'),
    'topic info': ('topic', 'info', '/cmd_vel'),
    'topic info -v': ('topic', 'info', '-v', '/cmd_vel'),
    'show Twist': ('interface', 'show', 'geometry_msgs/msg/Twist'),
    'topic find': ('topic', 'find', 'geometry_msgs/msg/Twist'),
    'echo': ('topic', 'echo', '/cmd_vel', '--once'),
    'echo --field': ('topic', 'echo', '--once', '/sensor/temperature', '--field', 'data'),
    'echo --flow-style': ('topic', 'echo', '--once', '--flow-style', '/cmd_vel'),
    'echo --csv': ('topic', 'echo', '--once', '--csv', '/cmd_vel'),
    'echo --no-arr --filter': ('topic', 'echo', '--once', '--no-arr', '--filter',
                               'm.data > -300', '/sensor/temperature'),
    'pub --once': ('topic', 'pub', '--once', '-w', '1', '/cmd_vel', 'geometry_msgs/msg/Twist',
                   TWIST),
    'pub header auto': ('topic', 'pub', '-t', '1', '-w', '0', '/pose',
                        'geometry_msgs/msg/PoseStamped',
                        '{header: "auto", pose: {position: {x: 1.0, y: 2.0, z: 3.0}}}'),
    'hz': ('topic', 'hz', '/sensor/temperature', '--duration', '2.5'),
    'bw': ('topic', 'bw', '/sensor/temperature', '--duration', '2.5'),
    'service list -t': ('service', 'list', '-t'),
    'service type': ('service', 'type', '/enable'),
    'service info': ('service', 'info', '/enable'),
    'service find': ('service', 'find', 'std_srvs/srv/SetBool'),
    'show SetBool': ('interface', 'show', 'std_srvs/srv/SetBool'),
    'param list': ('param', 'list'),
    'param get': ('param', 'get', '/sensor', 'sensor_rate'),
    'param describe': ('param', 'describe', '/sensor', 'sensor_rate'),
    'node info action': ('node', 'info', '/fibonacci_action_server'),
    'action list': ('action', 'list'),
    'action list -t': ('action', 'list', '-t'),
    'action type': ('action', 'type', '/fibonacci'),
    'action info': ('action', 'info', '/fibonacci'),
    'show Fibonacci': ('interface', 'show', 'test_msgs/action/Fibonacci'),
    'show-args': ('launch', 'robot_lab', 'robot.launch.py', '--show-args'),
    'doctor --report': ('doctor', '--report'),
}


# The commands that add endpoints of their own (a publisher, a subscription) run after the
# others: `topic info /cmd_vel` once counted `pub --once`'s publisher as a second one.
ADDS_ENDPOINTS = ('echo', 'pub', 'hz', 'bw')


@pytest.fixture(scope='module')
def out(system: dict[str, Proc]) -> dict[str, str]:
    # Four at a time: each command is a fresh DDS participant that must discover six nodes
    # within its window; six at once on a loaded 2-core CI machine once left three unseen.
    found: dict[str, str] = {}
    for adds in (False, True):
        names = [n for n in BATCH if n.startswith(ADDS_ENDPOINTS) == adds]
        with ThreadPoolExecutor(4) as pool:
            found.update(zip(names, pool.map(lambda n: ok(*BATCH[n]), names), strict=True))
    return found


def test_nodes_tutorial(out: dict[str, str]) -> None:
    executables, nodes, info = out['executables'], out['node list'], out['node info']
    assert executables.splitlines() == [
        'robot_lab controller_node', 'robot_lab fibonacci_node', 'robot_lab robot_node',
        'robot_lab sensor_node', 'robot_lab switch_node']
    assert nodes.splitlines() == ['/controller', '/fibonacci_action_server', '/my_sensor',
                                  '/robot', '/sensor', '/switch']
    lines = info.splitlines()
    # ros2node info: the name, then each section with `    /name: type` lines; an empty
    # section prints one empty line (print(*[], sep='\n')).
    assert lines[:5] == ['/my_sensor', '  Subscribers:', '', '  Publishers:',
                         '    /parameter_events: rcl_interfaces/msg/ParameterEvent']
    assert '    /sensor/temperature: std_msgs/msg/Float32' in lines
    assert '    /my_sensor/get_parameters: rcl_interfaces/srv/GetParameters' in lines
    assert lines[-6:] == ['  Service Clients:', '', '  Action Servers:', '', '  Action Clients:',
                          '']
    assert info.endswith('  Action Clients:\n\n')


def test_topics_tutorial(out: dict[str, str]) -> None:
    listed, typed, info, verbose, twist, found = (out[k] for k in (
        'topic list', 'topic list -t', 'topic info', 'topic info -v', 'show Twist',
        'topic find'))
    assert {'/cmd_vel', '/parameter_events', '/rosout', '/sensor/temperature'} <= set(
        listed.splitlines())
    assert '/cmd_vel [geometry_msgs/msg/Twist]' in typed.splitlines()
    assert info == 'Type: geometry_msgs/msg/Twist\nPublisher count: 1\nSubscription count: 1\n'
    assert verbose.startswith('Type: geometry_msgs/msg/Twist\n\nPublisher count: 1\n\n'
                              'Node name: controller\nNode namespace: /\n'
                              'Topic type: geometry_msgs/msg/Twist\nTopic type hash: RIHS01_')
    assert re.search(r'\nEndpoint type: SUBSCRIPTION\nGID: [0-9a-f.]+\nQoS profile:\n'
                     r'  Reliability: RELIABLE\n', verbose), verbose
    assert twist == (
        '# This expresses velocity in free space broken into its linear and angular parts.\n\n'
        'Vector3  linear\n\tfloat64 x\n\tfloat64 y\n\tfloat64 z\n'
        'Vector3  angular\n\tfloat64 x\n\tfloat64 y\n\tfloat64 z\n')
    assert found == '/cmd_vel\n'


def test_topic_echo_forms(out: dict[str, str]) -> None:
    block, field, flow, csv, no_arr = (out[k] for k in (
        'echo', 'echo --field', 'echo --flow-style', 'echo --csv', 'echo --no-arr --filter'))
    assert re.fullmatch(r'linear:\n  x: [-.\d]+\n  y: [-.\d]+\n  z: [-.\d]+\n'
                        r'angular:\n  x: [-.\d]+\n  y: [-.\d]+\n  z: [-.\d]+\n---\n', block), block
    assert re.fullmatch(r'[-\d.]+\n---\n', field), field
    assert re.fullmatch(r'\{linear: \{x: [-.\d]+, y: [-.\d]+, z: [-.\d]+\}, '
                        r'angular: \{x: [-.\d]+, y: [-.\d]+, z: [-.\d]+\}\}\n---\n', flow), flow
    assert re.fullmatch(r'([-.\d]+,){5}[-.\d]+\n', csv), csv
    assert re.fullmatch(r'data: [-.\d]+\n---\n', no_arr), no_arr


def test_topic_pub_hz_bw(out: dict[str, str]) -> None:
    once, stamped, hz, bw = (out[k] for k in ('pub --once', 'pub header auto', 'hz', 'bw'))
    # ros2topic pub: the wait line once a second while discovery goes on (twice on a loaded
    # host), then the loop and one repr per message
    waited = re.sub(r'^(Waiting for at least 1 matching subscription\(s\)\.\.\.\n)+', '', once)
    assert waited == f'publisher: beginning loop\npublishing #1: {TWIST_REPR}\n\n', once
    assert re.fullmatch(
        r'publisher: beginning loop\npublishing #1: geometry_msgs\.msg\.PoseStamped\(header='
        r'std_msgs\.msg\.Header\(stamp=builtin_interfaces\.msg\.Time\(sec=[1-9]\d+, '
        r"nanosec=\d+\), frame_id=''\), pose=.*\)\n\n", stamped), stamped
    assert re.match(r'average rate: \d+\.\d{3}\n\tmin: \d+\.\d{3}s max: \d+\.\d{3}s '
                    r'std dev: \d+\.\d{5}s window: \d+\n', hz), hz
    assert re.match(r'Subscribed to \[/sensor/temperature\]\n\d+ B/s from \d+ messages\n'
                    r'\tMessage size mean: 8 B min: 8 B max: 8 B\n', bw), bw


def test_services_tutorial(out: dict[str, str]) -> None:
    listed, kind, info, found, shown = (out[k] for k in (
        'service list -t', 'service type', 'service info', 'service find', 'show SetBool'))
    assert '/enable [std_srvs/srv/SetBool]' in listed.splitlines()
    assert '/get_state [std_srvs/srv/Trigger]' in listed.splitlines()
    assert kind == 'std_srvs/srv/SetBool\n'
    assert info == 'Type: std_srvs/srv/SetBool\nClients count: 0\nServices count: 1\n'
    assert found == '/enable\n'
    assert shown == ('bool data # e.g. for hardware enabling / disabling\n---\n'
                     'bool success   # indicate successful run of triggered service\n'
                     'string message # informational, e.g. for error messages\n')


def test_service_call_and_echo(system: dict[str, Proc]) -> None:
    """`ros2 service echo --flow-style` beside a call, as the introspection part does."""
    echoed: list[str] = []
    echo = threading.Thread(target=lambda: echoed.append(
        ok('service', 'echo', '--flow-style', '/enable', '-n', '2')))
    echo.start()
    deadline = time.monotonic() + 60  # the echo's subscription is in the graph
    while not robot_lab.topic_info('/enable/_service_event').subscribers:
        assert time.monotonic() < deadline, 'service echo never subscribed'
        time.sleep(0.05)
    called = ok('service', 'call', '/enable', 'std_srvs/srv/SetBool', '{data: true}')
    trigger = ok('service', 'call', '/get_state', 'std_srvs/srv/Trigger')
    assert called.removeprefix('waiting for service to become available...\n') == (
        'requester: making request: std_srvs.srv.SetBool_Request(data=True)\n\n'
        'response:\n'
        "std_srvs.srv.SetBool_Response(success=True, message='enabled')\n\n")
    assert trigger.removeprefix('waiting for service to become available...\n') == (
        'requester: making request: std_srvs.srv.Trigger_Request()\n\n'
        'response:\n'
        "std_srvs.srv.Trigger_Response(success=True, message='enabled')\n\n")
    echo.join(timeout=40)
    events = echoed[0] if echoed else ''
    if events.startswith('No publishers'):
        events = events.split('\n', 1)[1]
    first, second = events.split('---\n')[:2]
    assert re.fullmatch(r'\{info: \{event_type: REQUEST_RECEIVED, stamp: \{sec: \d+, nanosec: '
                        r'\d+\}, client_gid: \[[\d, ]+\], sequence_number: \d+\}, '
                        r'request: \[\{data: true\}\], response: \[\]\}\n', first), events
    assert 'event_type: RESPONSE_SENT' in second
    assert 'response: [{success: true, message: enabled}]' in second


def test_parameters_tutorial(out: dict[str, str], tmp_path: Path) -> None:
    listed, got, described = out['param list'], out['param get'], out['param describe']
    assert '/sensor:\n  noise_level\n  sensor_rate\n  start_type_description_service\n' \
        '  use_sim_time\n' in listed
    assert got == 'Integer value is: 10\n'
    assert described.startswith('Parameter name: sensor_rate\n  Type: integer\n  Description: ')
    assert ok('param', 'set', '/sensor', 'noise_level', '0.2') == 'Set parameter successful\n'
    dumped = ok('param', 'dump', '/sensor')  # `ros2 param dump /turtlesim > turtlesim.yaml`
    assert dumped == ('/sensor:\n  ros__parameters:\n    noise_level: 0.2\n    sensor_rate: 10\n'
                      '    start_type_description_service: true\n    use_sim_time: false\n\n')
    (tmp_path / 'sensor.yaml').write_text(dumped)
    loaded = ros2('param', 'load', '/sensor', 'sensor.yaml', cwd=tmp_path)
    assert loaded.stdout == ('Set parameter noise_level successful\n'
                             'Set parameter sensor_rate successful\n'
                             'Set parameter use_sim_time successful\n')
    assert loaded.stderr == ('Set parameter start_type_description_service failed: '
                             'Trying to set a read-only parameter: '
                             'start_type_description_service.\n')
    # `ros2 run turtlesim turtlesim_node --ros-args --params-file turtlesim.yaml`
    node = Proc([str(BIN / 'ros2'), 'run', 'robot_lab', 'sensor_node', '--ros-args',
                 '-r', '__node:=sensor', '-r', '__ns:=/loaded', '--params-file',
                 str(tmp_path / 'sensor.yaml')])
    try:
        node.wait_for(r'\[loaded\.sensor\]: Sensor node started', timeout=60)
    finally:
        node.stop()


def test_actions_tutorial(out: dict[str, str]) -> None:
    info_node, listed, typed, kind, info, shown = (out[k] for k in (
        'node info action', 'action list', 'action list -t', 'action type', 'action info',
        'show Fibonacci'))
    assert info_node.endswith('  Action Servers:\n    /fibonacci: test_msgs/action/Fibonacci\n'
                              '  Action Clients:\n\n')
    assert listed == '/fibonacci\n'
    assert typed == '/fibonacci [test_msgs/action/Fibonacci]\n'
    assert kind == 'test_msgs/action/Fibonacci\n'
    assert info == ('Action: /fibonacci\nAction clients: 0\nAction servers: 1\n'
                    '    /fibonacci_action_server\n')
    assert shown.split('---\n')[0].endswith('int32 order\n')
    # after the batch: a goal's client would be listed by `action info` (as in ros2cli)
    goal, feedback = ok_all(
        ('action', 'send_goal', '/fibonacci', 'test_msgs/action/Fibonacci', '{order: 3}'),
        ('action', 'send_goal', '/fibonacci', 'test_msgs/action/Fibonacci', '{order: 5}',
         '--feedback'))
    assert re.fullmatch(
        r'Waiting for an action server to become available\.\.\.\nSending goal:\n     order: 3\n\n'
        r'Goal accepted with ID: [0-9a-f]{32}\n\n'
        r'Result:\n    sequence:\n- 0\n- 1\n- 1\n- 2\n\n'
        r'Goal finished with status: SUCCEEDED\n', goal), goal
    # The tutorial's goal. Feedback and result travel on different DDS writers, which DDS
    # does not order, and rclpy drops feedback that arrives after the result (as ros2cli
    # does). With 50 ms steps the last feedback was missing in 1 run in 60 under load 18,
    # and all four once (stop 40's CI; not reproduced here, so the cause is a guess: the
    # whole goal fit in one 0.2 s heartbeat, the time a reliable writer takes to repair a
    # lost sample, and a late sample holds back the ones after it). With 0.3 s steps the
    # first feedback leads the result by 1.2 s.
    assert re.search(r'Goal accepted with ID: [0-9a-f]{32}\n\n'
                     r'(Feedback:\n    sequence:\n(- \d\n)+\n)+'
                     r'Result:\n    sequence:\n- 0\n- 1\n- 1\n- 2\n- 3\n- 5\n\n'
                     r'Goal finished with status: SUCCEEDED\n$', feedback), feedback
    shown = [re.findall(r'- (\d)', block) for block in
             re.findall(r'Feedback:\n    sequence:\n((?:- \d\n)+)', feedback)]
    assert shown == [['0', '1', '1', '2', '3', '5'][:n] for n in range(3, 3 + len(shown))]


def test_recording_tutorial(system: dict[str, Proc], tmp_path: Path) -> None:
    """`ros2 bag record -o subset /turtle1/cmd_vel /turtle1/pose`, info, play."""
    recorder = Proc([str(BIN / 'ros2'), 'bag', 'record', '-o', 'subset', '/cmd_vel',
                     '/sensor/temperature'], cwd=tmp_path)
    try:
        recorder.wait_for("Subscribed to topic '/cmd_vel'", timeout=60)
        recorder.wait_for("Subscribed to topic '/sensor/temperature'", timeout=60)
        recorder.wait_for('All requested topics are subscribed', timeout=60)
    finally:
        recorder.stop()  # Ctrl-C
    assert sorted(p.name for p in (tmp_path / 'subset').iterdir()) == ['metadata.yaml',
                                                                       'subset_0.mcap']
    info = ok('bag', 'info', 'subset', cwd=tmp_path)
    assert re.fullmatch(
        r'\nFiles:             subset_0\.mcap\nBag size:          [\d.]+ KiB\n'
        r'Storage id:        mcap\nROS Distro:        jazzy\nDuration:          [\d.]+s\n'
        r'Start:             \w{3} [ \d]\d \d{4} [\d:.]+ \([\d.]+\)\n'
        r'End:               \w{3} [ \d]\d \d{4} [\d:.]+ \([\d.]+\)\nMessages:          \d+\n'
        r'Topic information: Topic: /\S+ \| Type: \S+ \| Count: \d+ \| '
        r'Serialization Format: cdr\n'
        r'                   Topic: /\S+ \| Type: \S+ \| Count: \d+ \| '
        r'Serialization Format: cdr\nService:           0\nService information: \n', info), info
    played = ros2('bag', 'play', 'subset', cwd=tmp_path)
    assert played.returncode == 0 and 'Traceback' not in played.stderr, played.stderr


def test_launch_doctor_pkg_tutorials(out: dict[str, str], tmp_path: Path) -> None:
    args, report = out['show-args'], out['doctor --report']
    assert args.startswith("Arguments (pass arguments as '<name>:=<value>'):\n\n    '")
    headings = re.findall(r'^   (\S.*)$', report, flags=re.M)
    assert headings == ['PLATFORM INFORMATION', 'ROS 2 INFORMATION', 'RMW MIDDLEWARE',
                        'TOPIC LIST']
    assert 'middleware name    : rmw_fastrtps_cpp\n' in report
    assert 'topic               : /cmd_vel\n' in report
    created = ros2('pkg', 'create', '--build-type', 'ament_python', '--license', 'Apache-2.0',
                   '--node-name', 'my_node', 'my_package', cwd=tmp_path)
    assert created.returncode == 0, created.stderr
    assert (tmp_path / 'my_package' / 'my_package' / 'my_node.py').is_file()
    assert '<license>Apache-2.0</license>' in (tmp_path / 'my_package' / 'package.xml').read_text()


# ----------------------------------------------------------------------------- turtlesim
# The same tutorials on the kit's turtlesim, as they are written: these tests come last in
# the module, so the stand-ins' exact lists above never see turtlesim's nodes.

@pytest.fixture(scope='module')
def turtlesim(system: dict[str, Proc]) -> Iterator[Proc]:
    """`ros2 run turtlesim turtlesim_node` and `ros2 run turtlesim turtle_teleop_key` (the
    teleop in a terminal of its own: a pty)."""
    import pty

    from robot_lab.process import spawn

    sim = Proc([str(BIN / 'ros2'), 'run', 'turtlesim', 'turtlesim_node'])
    main, child = pty.openpty()
    teleop = spawn([str(BIN / 'ros2'), 'run', 'turtlesim', 'turtle_teleop_key'],
                   stdin=child, stdout=child, stderr=child)
    os.close(child)
    try:
        sim.wait_for(r'Spawning turtle \[turtle1\]', timeout=60)
        robot_lab.wait_for_nodes(['/turtlesim', '/teleop_turtle'], timeout=60)
        yield sim
    finally:
        os.write(main, b'q')
        try:
            teleop.wait(timeout=10)
        except subprocess.TimeoutExpired:
            teleop.kill()
            teleop.wait()
        os.close(main)
        sim.stop()


def test_turtlesim_services_tutorial(turtlesim: Proc) -> None:
    kind, found, info, spawn_type, listed = ok_all(
        ('service', 'type', '/clear'), ('service', 'find', 'std_srvs/srv/Empty'),
        ('service', 'info', '/clear'), ('interface', 'show', 'turtlesim/srv/Spawn'),
        ('service', 'list', '-t'))
    assert kind == 'std_srvs/srv/Empty\n'
    assert found == '/clear\n/reset\n'
    assert info == 'Type: std_srvs/srv/Empty\nClients count: 0\nServices count: 1\n'
    assert spawn_type == (
        'float32 x\nfloat32 y\nfloat32 theta\n'
        'string name # Optional.  A unique name will be created and returned if this is empty\n'
        '---\nstring name\n')
    for line in ('/clear [std_srvs/srv/Empty]', '/kill [turtlesim/srv/Kill]',
                 '/reset [std_srvs/srv/Empty]', '/spawn [turtlesim/srv/Spawn]',
                 '/turtle1/set_pen [turtlesim/srv/SetPen]',
                 '/turtle1/teleport_absolute [turtlesim/srv/TeleportAbsolute]',
                 '/turtle1/teleport_relative [turtlesim/srv/TeleportRelative]',
                 '/teleop_turtle/set_parameters [rcl_interfaces/srv/SetParameters]'):
        assert line in listed.splitlines(), listed
    assert ok('interface', 'show', 'std_srvs/srv/Empty') == '---\n'
    cleared = ok('service', 'call', '/clear', 'std_srvs/srv/Empty')
    assert cleared.removeprefix('waiting for service to become available...\n') == (
        'requester: making request: std_srvs.srv.Empty_Request()\n\n'
        'response:\nstd_srvs.srv.Empty_Response()\n\n')
    spawned = ok('service', 'call', '/spawn', 'turtlesim/srv/Spawn',
                 "{x: 2, y: 2, theta: 0.2, name: ''}")
    assert spawned.removeprefix('waiting for service to become available...\n') == (
        "requester: making request: turtlesim.srv.Spawn_Request(x=2.0, y=2.0, theta=0.2, "
        "name='')\n\nresponse:\nturtlesim.srv.Spawn_Response(name='turtle2')\n\n")


def test_turtlesim_parameters_tutorial(turtlesim: Proc, tmp_path: Path) -> None:
    listed, got = ok_all(('param', 'list', '/turtlesim'),
                         ('param', 'get', '/turtlesim', 'background_g'))
    assert listed.splitlines() == [
        '  background_b', '  background_g', '  background_r', '  holonomic',
        '  qos_overrides./parameter_events.publisher.depth',
        '  qos_overrides./parameter_events.publisher.durability',
        '  qos_overrides./parameter_events.publisher.history',
        '  qos_overrides./parameter_events.publisher.reliability',
        '  start_type_description_service', '  use_sim_time']
    assert got == 'Integer value is: 86\n'
    assert ok('param', 'set', '/turtlesim', 'background_r', '150') == \
        'Set parameter successful\n'
    dumped = ros2('param', 'dump', '/turtlesim')
    (tmp_path / 'turtlesim.yaml').write_text(dumped.stdout)  # `> turtlesim.yaml`
    assert dumped.stdout.startswith('/turtlesim:\n  ros__parameters:\n    background_b: 255\n'
                                    '    background_g: 86\n    background_r: 150\n')
    assert ('    qos_overrides:\n      /parameter_events:\n        publisher:\n'
            '          depth: 1000\n          durability: volatile\n'
            '          history: keep_last\n          reliability: reliable\n'
            ) in dumped.stdout
    loaded = ros2('param', 'load', '/turtlesim', 'turtlesim.yaml', cwd=tmp_path)
    assert 'Set parameter background_r successful\n' in loaded.stdout
    assert ("Set parameter qos_overrides./parameter_events.publisher.depth failed: parameter "
            "'qos_overrides./parameter_events.publisher.depth' cannot be set because it is "
            "read-only\n") in loaded.stderr
    ok('param', 'set', '/turtlesim', 'background_r', '69')


def test_turtlesim_actions_tutorial(turtlesim: Proc) -> None:
    sim_info, teleop_info, typed, kind, info, shown = ok_all(
        ('node', 'info', '/turtlesim'), ('node', 'info', '/teleop_turtle'),
        ('action', 'list', '-t'), ('action', 'type', '/turtle1/rotate_absolute'),
        ('action', 'info', '/turtle1/rotate_absolute'),
        ('interface', 'show', 'turtlesim/action/RotateAbsolute'))
    assert ('  Action Servers:\n'
            '    /turtle1/rotate_absolute: turtlesim/action/RotateAbsolute\n') in sim_info
    assert sim_info.endswith('  Action Clients:\n\n'), sim_info
    assert teleop_info.endswith(
        '  Action Clients:\n    /turtle1/rotate_absolute: turtlesim/action/RotateAbsolute\n')
    assert '/turtle1/rotate_absolute [turtlesim/action/RotateAbsolute]' in typed.splitlines()
    assert kind == 'turtlesim/action/RotateAbsolute\n'
    assert info == ('Action: /turtle1/rotate_absolute\nAction clients: 1\n    /teleop_turtle\n'
                    'Action servers: 1\n    /turtlesim\n')
    assert shown == ('# The desired heading in radians\nfloat32 theta\n---\n'
                     '# The angular displacement in radians to the starting position\n'
                     'float32 delta\n---\n# The remaining rotation in radians\n'
                     'float32 remaining\n')
    goal = ok('action', 'send_goal', '/turtle1/rotate_absolute',
              'turtlesim/action/RotateAbsolute', '{theta: 1.57}')
    assert re.fullmatch(
        r'Waiting for an action server to become available\.\.\.\nSending goal:\n'
        r'     theta: 1\.57\n\nGoal accepted with ID: [0-9a-f]{32}\n\n'
        r'Result:\n    delta: -1\.5\d*\n\nGoal finished with status: SUCCEEDED\n', goal), goal
    turtlesim.wait_for(r'\[turtlesim\]: Rotation goal completed successfully')
    feedback = ok('action', 'send_goal', '/turtle1/rotate_absolute',
                  'turtlesim/action/RotateAbsolute', '{theta: -1.57}', '--feedback')
    assert re.search(r'Goal accepted with ID: [0-9a-f]{32}\n\n'
                     r'(Feedback:\n    remaining: -?[\d.]+(e-\d+)?\n\n)+'
                     r'Result:\n    delta: [\d.]+\n\n'
                     r'Goal finished with status: SUCCEEDED\n$', feedback), feedback
