"""The simulator process's world control and statistics, over its own socket (no ROS)."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import BIN, Proc

from robot_lab.sim.control import bridge_hint, gz_topics, world_control
from robot_lab.sim.create import main as create_main
from robot_lab.sim.sample_robot import diffbot_urdf
from robot_lab.sim.transport import connect

pytestmark = pytest.mark.no_ros  # the simulator's own transport only


@pytest.fixture(scope='module')
def simulation() -> Iterator[Proc]:
    # a partition of this module's own, whichever domain others use
    os.environ['GZ_PARTITION'] = f'test_sim_control_{os.getpid()}'
    process = Proc([str(BIN.parent / 'lib' / 'ros_gz_sim' / 'gz_sim'), '-r', 'room.sdf'])
    try:
        process.wait_for(r'Serving partition', timeout=30)
        yield process
    finally:
        process.stop()
        del os.environ['GZ_PARTITION']


def _stats() -> dict[str, object]:
    connection = connect()
    assert connection is not None
    connection.send({'op': 'sub', 'topic': '/world/room/stats'})
    frame = connection.receive()
    connection.close()
    assert frame is not None
    return dict(frame['msg'])


def test_pause_step_and_reset(simulation: Proc) -> None:
    paused = world_control(pause=True)
    assert paused['paused'] is True
    assert world_control()['iterations'] == paused['iterations']  # nothing ran meanwhile
    stepped = world_control(step=250)
    assert stepped['iterations'] == paused['iterations'] + 250
    assert world_control(reset=True)['iterations'] == 0
    assert _stats()['paused'] is True
    running = world_control(pause=False)
    assert running['paused'] is False


def test_the_real_time_factor_is_reported(simulation: Proc) -> None:
    world_control(pause=False)
    stats = _stats()
    stats = _stats()  # the second has a whole interval of running behind it
    assert stats['paused'] is False
    assert 0.5 < float(str(stats['real_time_factor'])) < 1.5
    assert '/world/room/stats' in gz_topics() and '/clock' in gz_topics()


def test_gz_commands_as_the_tutorials_type_them(simulation: Proc) -> None:
    def gz(*args: str) -> str:
        done = subprocess.run([str(BIN / 'gz'), *args], capture_output=True, text=True,
                              timeout=30, check=False)
        assert done.returncode == 0, done.stderr
        return done.stdout

    assert "robot_lab's simulator" in gz('--version') and 'not Gazebo' in gz('--version')
    assert '/clock' in gz('topic', '-l').split()
    clock = gz('topic', '-e', '-t', '/clock', '-n', '1')
    assert clock.startswith('header {') and 'sim {' in clock
    gz('service', '-s', '/world/room/control', '--reqtype', 'gz.msgs.WorldControl',
       '--reptype', 'gz.msgs.Boolean', '--timeout', '3000', '--req', 'pause: true')
    assert world_control()['paused'] is True
    gz('service', '-s', '/world/room/control', '--req', 'pause: false')
    assert world_control()['paused'] is False


def test_an_unbridged_topic_gets_the_bridge_argument_that_would_bridge_it(
        simulation: Proc) -> None:
    world_control(pause=False)
    assert create_main(['-string', diffbot_urdf(), '-name', 'hinted', '-z', '0.051']) == 0
    connection = connect()
    assert connection is not None
    connection.send({'op': 'sub', 'topic': '/scan'})
    assert connection.receive() is not None  # the simulation publishes its gz /scan now
    connection.close()
    hint = bridge_hint('/scan')
    assert hint == ('nothing publishes /scan: the simulator publishes gz topic /scan; bridge it '
                    'with: ros2 run ros_gz_bridge parameter_bridge '
                    '/scan@sensor_msgs/msg/LaserScan[gz.msgs.LaserScan')
    assert bridge_hint('/no_such_topic') is None


def test_create_spawns_an_sdf_model_from_a_file_and_refuses_another_world(
        simulation: Proc, tmp_path: Path) -> None:
    from robot_lab.sim.world import KIT_RESOURCES

    model = KIT_RESOURCES / 'models' / 'box_obstacle' / 'model.sdf'
    assert create_main(['-file', str(model), '-x', '1.5', '-y', '-0.5']) == 0  # its own name
    simulation.wait_for(r"Spawned SDF model 'box_obstacle' at \[1.5, -0.5, 0.0\]")
    crate = tmp_path / 'crate.sdf'
    crate.write_text('<sdf version="1.9"><model name="crate"><link name="body"><collision '
                     'name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>'
                     '</collision></link></model></sdf>')
    assert create_main(['-file', str(crate), '-name', 'crate_1', '-z', '0.5']) == 0
    simulation.wait_for(r"Spawned SDF model 'crate_1'")
    assert create_main(['-file', str(crate), '-name', 'crate_1']) == 1  # the name is taken
    assert create_main(['-file', str(crate), '-name', 'crate_2', '-world', 'maze']) == 1
    simulation.wait_for(r"no world 'maze' here: the simulation runs 'room'")
    world = KIT_RESOURCES / 'worlds' / 'empty.sdf'
    assert create_main(['-file', str(world)]) == 1  # a world is gz sim's, not create's
    simulation.wait_for(r'no <sdf><model> in it')


def test_options_and_fields_the_kit_has_nothing_for_are_one_line_each(
        simulation: Proc) -> None:
    from robot_lab.sim.server import _ignored_options, _parser

    args = _parser().parse_args(['-r', '--render-engine', 'ogre2', '--physics-engine',
                                 'gz-physics-bullet-featherstone-plugin', 'room.sdf'])
    assert _ignored_options(args) == [
        "[Wrn] gz sim --render-engine ogre2: robot_lab's simulator has no renderer; ignored",
        "[Wrn] gz sim --physics-engine gz-physics-bullet-featherstone-plugin: robot_lab's "
        'simulator runs MuJoCo; ignored']
    done = subprocess.run([str(BIN / 'gz'), 'service', '-s', '/world/room/control', '--req',
                           'pause: false, seed: 3, reset {model_only: true}, speed: 2'],
                          capture_output=True, text=True, timeout=30, check=False)
    assert done.returncode == 0
    assert done.stderr == ('gz service: reset.model_only, seed: Gazebo does not honour it '
                           'either; ignored\n'
                           'gz service: speed: not a gz.msgs.WorldControl field; ignored\n')


def test_gz_service_create_spawns_as_gazebos_spawn_tutorial_types_it(
        simulation: Proc, tmp_path: Path) -> None:
    urdf = tmp_path / 'robot.urdf'
    urdf.write_text(diffbot_urdf())

    def create(request: str) -> str:
        done = subprocess.run([str(BIN / 'gz'), 'service', '-s', '/world/room/create',
                               '--reqtype', 'gz.msgs.EntityFactory', '--reptype',
                               'gz.msgs.Boolean', '--timeout', '1000', '--req', request],
                              capture_output=True, text=True, timeout=30, check=False)
        assert done.returncode == 0, done.stderr
        return done.stdout

    assert create(f'sdf_filename: "{urdf}", name: "urdf_model", pose: {{position: '
                  f'{{x: -1, y: 1, z: 0.051}}}}') == 'data: true\n\n'
    simulation.wait_for(r"Spawned 'urdf_model' \(\d+ links\) at \[-1.0, 1.0, 0.051\]")
    sdf = ('<?xml version=\\"1.0\\" ?><sdf version=\\"1.6\\"><model name=\\"cube\\"><static>'
           'true</static><link name=\\"l\\"/></model></sdf>')
    assert create(f'sdf: "{sdf}", pose: {{position: {{x: 1, y: 1}}}}') == 'data: true\n\n'
    simulation.wait_for(r"Spawned SDF model 'cube' at \[1.0, 1.0, 0.0\]")
    assert create(f'sdf: "{sdf}"') == 'data: false\n\n'  # the name is taken
    assert create(f'sdf: "{sdf}", name: "cube", allow_renaming: true') == 'data: true\n\n'
    simulation.wait_for(r"Spawned SDF model 'cube_1'")


def test_a_bridge_yaml_reads_as_upstreams_bridge_config(tmp_path: Path) -> None:
    from robot_lab.sim.bridge import BridgeSpec, parse_bridge_config

    config = tmp_path / 'bridge.yaml'
    config.write_text("""\
- ros_topic_name: "scan"
  ros_type_name: "sensor_msgs/msg/LaserScan"
  gz_type_name: "gz.msgs.LaserScan"
  direction: GZ_TO_ROS
- gz_topic_name: "/odom"
  ros_type_name: "nav_msgs/msg/Odometry"
  gz_type_name: "gz.msgs.Odometry"
  publisher_queue: 5
  lazy: true
  qos_depth: 3
""")
    warnings: list[str] = []
    assert parse_bridge_config(str(config), warnings.append) == [
        BridgeSpec('scan', 'scan', 'sensor_msgs/msg/LaserScan', 'gz.msgs.LaserScan',
                   'GZ_TO_ROS'),
        BridgeSpec('/odom', '/odom', 'nav_msgs/msg/Odometry', 'gz.msgs.Odometry',
                   'BIDIRECTIONAL', publisher_queue=5, lazy=True)]
    assert warnings == [f"{config}:5: 'qos_depth' is not a ros_gz_bridge entry key "
                        f'(direction, gz_topic_name, gz_type_name, lazy, publisher_queue, '
                        f'ros_topic_name, ros_type_name, subscriber_queue, topic_name); ignored']
    config.write_text('- topic_name: a\n  ros_topic_name: b\n  ros_type_name: x\n'
                      '  gz_type_name: y\n')
    with pytest.raises(SystemExit, match=f'{config}:1: topic_name and ros_topic_name are '
                                         f'mutually exclusive'):
        parse_bridge_config(str(config))


def test_a_client_that_stops_reading_is_dropped_not_waited_for(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A hung bridge once froze the whole simulation: the server's send to it blocked.
    Now a send that cannot go within SEND_TIMEOUT drops that client; the world goes on."""
    import socket
    import threading
    from types import SimpleNamespace

    from robot_lab.sim import server as server_module
    from robot_lab.sim.transport import Connection

    monkeypatch.setattr(server_module, 'SEND_TIMEOUT', 0.2)
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(str(tmp_path / 'sim.sock'))
    listener.listen(1)
    server = server_module.Server(SimpleNamespace(on_publish=None), listener)  # type: ignore[arg-type]
    client = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    client.connect(str(tmp_path / 'sim.sock'))
    subscribed = threading.Event()
    Connection(client).send({'op': 'sub', 'topic': '/big'})
    while not subscribed.is_set():  # the server's reader thread takes the subscription
        with server.lock:
            if server.subscribers.get('/big'):
                subscribed.set()
        subscribed.wait(0.01)
    big = {'data': 'x' * 4_000_000}  # more than a socket buffer holds: the send must wait
    server.publish('/big', 'gz.msgs.StringMsg', big)  # returns after 0.2 s, not never
    assert not server.subscribers['/big']
    client.close()
    listener.close()


def test_a_simulation_in_another_network_namespace_is_not_this_ones(
        simulation: Proc) -> None:
    """Gazebo finds a partition's simulation over the network, so one in another network
    namespace is another's. Two test runs side by side, each in a namespace of its own with
    the same domains, met in one socket: the second's simulation refused to start ("a
    simulation already runs") and its `create` spawned into the first's world."""
    gz_sim = str(BIN.parent / 'lib' / 'ros_gz_sim' / 'gz_sim')
    here = subprocess.run([gz_sim, '-r', 'empty.sdf', '--iterations', '1'],
                          capture_output=True, text=True, timeout=60)
    assert 'a simulation already runs in partition' in here.stdout, here.stdout
    there = subprocess.run(
        ['unshare', '--net', gz_sim, '-r', 'empty.sdf', '--iterations', '50'],
        capture_output=True, text=True, timeout=60)
    assert there.returncode == 0 and 'Serving partition' in there.stdout, there.stdout
    assert 'already runs' not in there.stdout, there.stdout
    connection = connect()  # this namespace's simulation still answers here
    assert connection is not None and simulation.popen.poll() is None
    connection.close()
