"""A world started without -r waits, paused, as Gazebo's does; world control starts it.

One simulator process, started as `gz sim room.sdf` (no -r): its log says it is paused and
gives the exact `gz service` line that starts it; /clock holds at 0 and the statistics say
`paused: true` until that line is run. Then, through `parameter_bridge
/world/room/control@ros_gz_interfaces/srv/ControlWorld`, `ros2 service call` pauses and
runs it from ROS, as ros_gz_bridge's README does it.
"""

from __future__ import annotations

import os
import shlex
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import BIN, Proc

from robot_lab.sim.control import gz_topics, world_control
from robot_lab.sim.transport import connect


def _sim_ns(message: dict[str, object]) -> int:
    sim = message['sim_time'] if 'sim_time' in message else message['sim']
    assert isinstance(sim, dict)
    return int(sim['sec']) * 1_000_000_000 + int(sim['nsec'])


def _ns(stamp: object) -> int:
    assert isinstance(stamp, dict)
    return int(stamp['sec']) * 1_000_000_000 + int(stamp['nsec'])


def _messages(topic: str, count: int) -> list[dict[str, object]]:
    """The next `count` messages the simulator publishes on its own (gz) `topic`."""
    connection = connect()
    assert connection is not None
    try:
        connection.send({'op': 'sub', 'topic': topic})
        out: list[dict[str, object]] = []
        while len(out) < count:
            frame = connection.receive()
            assert frame is not None, 'the simulator closed the connection'
            out.append(dict(frame['msg']))
        return out
    finally:
        connection.close()


@pytest.fixture(scope='module')
def paused_world() -> Iterator[Proc]:
    process = Proc([str(BIN.parent / 'lib' / 'ros_gz_sim' / 'gz_sim'), 'room.sdf'])
    try:
        process.wait_for(r'Serving partition', timeout=60)
        yield process
    finally:
        process.stop()


def test_without_r_it_waits_paused_and_says_how_to_start_it(paused_world: Proc) -> None:
    command = ("gz service -s /world/room/control --reqtype gz.msgs.WorldControl "
               "--reptype gz.msgs.Boolean --timeout 3000 --req 'pause: false'")
    said = paused_world.wait_for(r'Paused.*').group(0)
    assert command in said and 'pass -r' in said
    first = [line for line in paused_world.lines if line.startswith('[')][:4]
    assert any('Paused' in line for line in first), first  # among its first lines
    clocks = _messages('/clock', 3)  # published while paused, held at 0
    assert [_sim_ns(c) for c in clocks] == [0, 0, 0]
    stats = _messages('/world/room/stats', 2)
    assert all(s['paused'] is True and s['iterations'] == 0 for s in stats)
    assert all(_ns(s['real_time']) == 0 for s in stats)  # Gazebo's real time: running only

    done = subprocess.run([str(BIN / 'gz'), *shlex.split(command)[1:]], capture_output=True,
                          text=True, timeout=30, check=False)
    assert done.returncode == 0 and done.stdout.startswith('data: true'), done.stderr
    paused_world.wait_for(r'World running')
    first_ns = _sim_ns(_messages('/clock', 1)[0])
    later = _messages('/world/room/stats', 2)[-1]
    assert later['paused'] is False and _sim_ns(later) > first_ns  # time moves now

    # a reset while running rewinds real time with sim time (Gazebo's rewind), and the
    # schedule starts afresh from it: no burst of steps the old one still owed
    while int(str((before := _messages('/world/room/stats', 1)[0])['iterations'])) < 500:
        pass
    world_control(reset=True)
    after = _messages('/world/room/stats', 1)[0]
    assert _ns(after['real_time']) < _ns(before['real_time'])
    assert int(str(after['iterations'])) <= _ns(after['real_time']) / 1e6 + 50, after
    world_control(pause=True)


@pytest.fixture(scope='module')
def control_bridge(paused_world: Proc) -> Iterator[Proc]:
    process = Proc([str(BIN / 'ros2'), 'run', 'ros_gz_bridge', 'parameter_bridge',
                    '/world/room/control@ros_gz_interfaces/srv/ControlWorld',
                    '/world/default/control@ros_gz_interfaces/srv/ControlWorld'
                    '@gz.msgs.WorldControl@gz.msgs.Boolean'])
    try:
        process.wait_for(r'Creating ROS service bridge: \[/world/default/control', timeout=60)
        yield process
    finally:
        process.stop()


def test_ros_service_call_runs_and_pauses_the_world(control_bridge: Proc) -> None:
    from ros_gz_interfaces.srv import ControlWorld

    from robot_lab.rclpy_session import session

    world_control(pause=True)
    done = subprocess.run(
        [str(BIN / 'ros2'), 'service', 'call', '/world/room/control',
         'ros_gz_interfaces/srv/ControlWorld', '{world_control: {pause: false}}'],
        capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0 and 'success=True' in done.stdout, done.stdout + done.stderr
    assert world_control()['paused'] is False

    node = session().node
    request = ControlWorld.Request()
    request.world_control.pause, request.world_control.multi_step = True, 50  # then paused
    for name, succeeds in (('/world/room/control', True), ('/world/default/control', False)):
        client = node.create_client(ControlWorld, name)
        try:
            assert client.wait_for_service(timeout_sec=20)
            before = world_control()['iterations']
            reply = _call(client, request)
            assert reply.success is succeeds, name  # no world 'default': success false
            if succeeds:
                state = world_control()
                assert state['paused'] is True and state['iterations'] >= before + 50
        finally:
            node.destroy_client(client)


def _call(client: Any, request: Any) -> Any:
    """The reply, as the session's executor (its own thread) delivers it."""
    answered = threading.Event()
    future = client.call_async(request)
    future.add_done_callback(lambda _: answered.set())
    assert answered.wait(timeout=20), 'no reply within 20 s'
    return future.result()


def test_create_reads_the_description_from_ros_parameters(paused_world: Proc,
                                                           tmp_path: Path) -> None:
    """Upstream's `-param P` (the XML in the create node's parameter P, as a launch file's
    `parameters=[{'robot_description': ...}]` gives it) and its ROS-parameter form
    (`file`, `name`, `x` ...: what upstream's gz_spawn_model.launch.py passes)."""
    from robot_lab.sim.sample_robot import diffbot_urdf

    params = tmp_path / 'create.yaml'
    params.write_text(yaml.safe_dump({'ros_gz_sim': {'ros__parameters': {
        'robot_description': diffbot_urdf()}}}))

    def create(*args: str) -> str:
        done = subprocess.run([str(BIN / 'ros2'), 'run', 'ros_gz_sim', 'create', *args],
                              capture_output=True, text=True, timeout=60, check=False)
        assert done.returncode == 0, done.stdout + done.stderr
        return done.stdout

    world_control(pause=True)
    assert 'Entity creation successful.' in create(
        '-param', 'robot_description', '-name', 'by_param', '-z', '0.051',
        '--ros-args', '--params-file', str(params))
    paused_world.wait_for(r"Spawned 'by_param' \(\d+ links\) at \[0.0, 0.0, 0.051\]")
    # advertised at once, as gz-sim's systems do, though paused it has published none yet
    assert gz_topics()['/scan'] == 'gz.msgs.LaserScan'
    assert world_control()['paused'] is True
    sdf = tmp_path / 'crate.sdf'
    sdf.write_text('<sdf version="1.9"><model name="crate"><static>true</static><link '
                   'name="l"/></model></sdf>')
    # upstream's gz_spawn_model.launch.py passes them so, as a launch file's parameters
    launched = subprocess.run(
        [str(BIN / 'ros2'), 'launch', 'ros_gz_sim', 'gz_spawn_model.launch.py', f'file:={sdf}',
         'entity_name:=by_parameter', 'x:=2.0'],
        capture_output=True, text=True, timeout=60, check=False)
    assert 'Entity creation successful.' in launched.stdout, launched.stdout + launched.stderr
    paused_world.wait_for(r"Spawned SDF model 'by_parameter' at \[2.0, 0.0, 0.0\]")


def test_a_ros_world_control_converts_as_ros_gz_bridge_does() -> None:
    """As gz-sim processes it: pause always applies (left out, it runs); steps only when
    pausing; what Gazebo itself ignores is named, for the bridge's one warning line."""
    from ros_gz_interfaces.msg import WorldControl

    from robot_lab.sim.conversions import world_control_request

    stepping = WorldControl()
    stepping.pause, stepping.multi_step = True, 5
    assert world_control_request(stepping) == ({'pause': True, 'multi_step': 5,
                                                'reset': False}, [])
    stepping.pause = False  # Gazebo steps only when pausing: this one just runs
    assert world_control_request(stepping)[0] == {'pause': False, 'multi_step': 0,
                                                  'reset': False}
    odd = WorldControl()
    odd.seed, odd.run_to_sim_time.sec = 3, 2
    odd.reset.model_only, odd.reset.time_only = True, True
    assert world_control_request(odd) == (
        {'pause': False, 'multi_step': 0, 'reset': True, 'run_to_sim_time': 2_000_000_000},
        ['reset.model_only', 'seed'])


def test_run_to_sim_time_runs_there_and_pauses(paused_world: Proc) -> None:
    """Harmonic's WorldControl.run_to_sim_time: run, then pause at exactly that time."""
    start = world_control(pause=True)['iterations'] * 1_000_000  # room.sdf: 1 ms steps
    target = start + 200_000_000
    done = subprocess.run(
        [str(BIN / 'gz'), 'service', '-s', '/world/room/control', '--reqtype',
         'gz.msgs.WorldControl', '--reptype', 'gz.msgs.Boolean', '--timeout', '3000', '--req',
         f'pause: false, run_to_sim_time: {{sec: {target // 10**9}, nsec: {target % 10**9}}}'],
        capture_output=True, text=True, timeout=30, check=False)
    assert done.returncode == 0, done.stderr
    connection = connect()
    assert connection is not None
    try:
        connection.send({'op': 'sub', 'topic': '/world/room/stats'})
        for _ in range(200):  # 10 a second: 20 s at most
            frame = connection.receive()
            assert frame is not None
            if frame['msg']['paused']:
                break
        assert frame['msg']['paused'] and _sim_ns(frame['msg']) == target
    finally:
        connection.close()


def test_gz_server_launch_runs_a_world_string_at_once() -> None:
    """ros_gz_sim's gz_server.launch.py (world_sdf_file or world_sdf_string): upstream's
    gzserver runs its world unpaused, so this one runs without any -r."""
    from robot_lab.sim.transport import socket_path

    partition = f'gz_server_{os.getpid()}'
    world = '<sdf version="1.9"><world name="from_string"></world></sdf>'
    server = Proc([str(BIN / 'ros2'), 'launch', 'ros_gz_sim', 'gz_server.launch.py',
                   f'world_sdf_string:={world}', 'use_composition:=True'],
                  env={**os.environ, 'GZ_PARTITION': partition})
    try:
        server.wait_for(r'Serving partition', timeout=60)
        assert not any('Paused' in line for line in server.lines)
        server.wait_for(r'use_composition: .* runs as its own process')
        connection = connect(socket_path({'GZ_PARTITION': partition}))
        assert connection is not None
        try:
            connection.send({'op': 'sub', 'topic': '/world/from_string/stats'})
            frame = connection.receive()
            assert frame is not None and frame['msg']['paused'] is False
        finally:
            connection.close()
    finally:
        server.stop()
