"""tf2 over DDS and the tools the tf2 pages run: tf2_ros_py's listener/broadcaster test as
facts; static_transform_publisher (Jazzy flags, the deprecated positional form), tf2_echo,
tf2_monitor, view_frames (.gv + .pdf with no Graphviz). The tutorials' own files, in a
student's colcon package, are tests/test_tf2_tutorials.py.
"""

from __future__ import annotations

import math
import re
import subprocess
import time
from pathlib import Path

import pytest
import rclpy
from conftest import BIN, Proc, cli_ok
from geometry_msgs.msg import TransformStamped

from robot_lab.tf2.static_publisher import ParseError, parse_args

STATIC = ['ros2', 'run', 'tf2_ros', 'static_transform_publisher']


def _translation(proc: Proc, timeout: float = 20.0) -> tuple[float, float, float]:
    found = proc.wait_for(r'^- Translation: \[(\S+), (\S+), (\S+)\]$', timeout=timeout)
    return float(found[1]), float(found[2]), float(found[3])


# --- static_transform_publisher's command line (pure) ---------------------------------------

def test_static_publisher_parses_jazzy_flags_and_the_old_forms() -> None:
    new = parse_args(['p', '--x', '1', '--yaw', '1.5707963267948966', '--frame-id', 'world',
                      '--child-frame-id', 'cam'])
    assert (new.translation, new.frame_id, new.child_frame_id) == ([1.0, 0.0, 0.0], 'world',
                                                                   'cam')
    assert new.rotation[2] == pytest.approx(math.sqrt(0.5))
    old = parse_args(['p', '0', '0', '1', '0', '0', '0', 'world', 'cam'])  # x y z yaw pitch roll
    assert (old.translation, old.rotation) == ([0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0])
    quat = parse_args(['p', '1', '2', '3', '0', '0', '0', '1', 'a', 'b'])
    assert (quat.translation, quat.rotation, quat.child_frame_id) == ([1, 2, 3], [0, 0, 0, 1],
                                                                      'b')
    for argv, why in (
            (['p', '--x', '1'], 'Frame id must not be empty'),
            (['p', '--frame-id', 'a'], 'Child frame id must not be empty'),
            (['p', '--qx', '0', '--roll', '1', '--frame-id', 'a', '--child-frame-id', 'b'],
             'Cannot specify both quaternion and Euler rotations'),
            (['p', '--x', 'one'], 'Failed to parse --x argument as float'),
            (['p', '--x'], 'Not enough arguments for --x'),
            (['p', 'a', 'b'], 'Extra unparsed arguments on command-line'),
            (['p', '--x', '1', '0', '0', '1', '0', '0', '0', 'world', 'cam'],
             'Cannot specify both new-style (flags) and old-style (arguments)')):
        with pytest.raises(ParseError) as caught:
            parse_args(argv)
        assert str(caught.value) == why


def test_tf2_echo_refuses_its_arguments_as_upstream(capsys: pytest.CaptureFixture[str]) -> None:
    from robot_lab.tf2.echo import echo_main

    for argv, code in ((['tf2_echo'], 1), (['tf2_echo', 'a', 'b', 'foo'], 2),
                       (['tf2_echo', 'a', 'b', '1.0foo'], 3)):
        with pytest.raises(SystemExit) as caught:
            echo_main(argv)
        assert caught.value.code == code
    out, err = capsys.readouterr()
    assert out.startswith('Usage: tf2_echo source_frame target_frame [echo_rate]\n\n')
    assert out.endswith('Default echo rate is 1 if echo_rate is not given.\n')
    assert err.splitlines() == [
        "Failed to convert rate argument 'foo' to a floating-point number",
        "Failed to convert rate argument '1.0foo' to a floating-point number"]


# --- tf2_ros_py/test/test_listener_and_broadcaster.py, as facts -----------------------------

def _msg(parent: str, child: str, sec: float) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp = rclpy.time.Time(nanoseconds=round(sec * 1e9)).to_msg()
    t.transform.translation.x, t.transform.translation.y = 42.0, -3.14
    t.transform.rotation.w = 1.0
    return t


def test_broadcasters_reach_a_listener_over_dds() -> None:
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    from robot_lab.tf2.broadcasters import StaticTransformBroadcaster, TransformBroadcaster
    from robot_lab.tf2.buffer import Buffer
    from robot_lab.tf2.exceptions import ExtrapolationException
    from robot_lab.tf2.listener import TransformListener

    context = Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node('test_broadcaster_listener', context=context)
        buffer = Buffer()
        broadcaster, static = TransformBroadcaster(node), StaticTransformBroadcaster(node)
        listener = TransformListener(buffer=buffer, node=node, spin_thread=False)
        assert listener.tf_sub.qos_profile.depth == 100
        assert listener.tf_static_sub.qos_profile.durability.name == 'TRANSIENT_LOCAL'
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)

        def spin_until(frame: str, stamp: object) -> None:
            deadline = time.monotonic() + 10
            while not buffer.can_transform_core('foo', frame, stamp)[0]:
                assert time.monotonic() < deadline, buffer.all_frames_as_string()
                executor.spin_once(timeout_sec=0.1)

        sent = _msg('foo', 'bar', 1.0)
        broadcaster.sendTransform(sent)
        spin_until('bar', sent.header.stamp)
        assert buffer.lookup_transform('foo', 'bar', sent.header.stamp) == sent
        coro = buffer.lookup_transform_async('foo', 'bar', sent.header.stamp)
        with pytest.raises(StopIteration) as done:
            coro.send(None)
        assert done.value.value == sent

        broadcaster.sendTransform([_msg('foo', 'baz', 0.3), _msg('foo', 'baz', 0.2)])
        spin_until('baz', rclpy.time.Time(nanoseconds=300_000_000))
        with pytest.raises(ExtrapolationException,
                           match='Lookup would require extrapolation into the past'):
            buffer.lookup_transform('foo', 'baz', rclpy.time.Time(seconds=0.1).to_msg())
        with pytest.raises(ExtrapolationException,
                           match='Lookup would require extrapolation into the future'):
            buffer.lookup_transform('foo', 'baz', rclpy.time.Time(seconds=0.4).to_msg())

        static.sendTransform(_msg('foo', 'fixed', 1.1))
        spin_until('fixed', rclpy.time.Time(seconds=1.5))
        got = buffer.lookup_transform('foo', 'fixed', rclpy.time.Time(seconds=1.5).to_msg())
        assert (got.header.stamp.sec, got.header.stamp.nanosec) == (1, 500_000_000)
        assert got.transform.translation.x == 42.0
        executor.shutdown()
        node.destroy_node()
    finally:
        rclpy.utilities.try_shutdown(context=context)


def test_a_kernels_tf_buffer_hears_the_graph() -> None:
    """robot_lab.tf_buffer(): a Buffer the session keeps filled, as a notebook cell uses."""
    from rclpy.duration import Duration

    import robot_lab
    from robot_lab.rclpy_session import session
    from robot_lab.tf2.broadcasters import StaticTransformBroadcaster

    buffer = robot_lab.tf_buffer()
    node = rclpy.create_node('kernel_static_broadcaster', context=session().context)
    try:
        StaticTransformBroadcaster(node).sendTransform(_msg('world', 'camera', 0.0))
        got = buffer.lookup_transform('world', 'camera', rclpy.time.Time(),
                                      timeout=Duration(seconds=10))
        assert got.transform.translation.x == 42.0
        assert robot_lab.tf_buffer() is buffer
    finally:
        node.destroy_node()



def test_a_kernels_tf_buffer_closes_its_hidden_node() -> None:
    """`tf_buffer().close()` takes its listener node off the graph (a notebook's "nothing
    left running"); the next tf_buffer() is a fresh buffer that hears the graph again."""
    import os

    from rclpy.duration import Duration

    import robot_lab
    from robot_lab.rclpy_session import session
    from robot_lab.tf2.broadcasters import StaticTransformBroadcaster

    sess = session()
    hidden = f'_robot_lab_tf_{os.getpid()}'
    buffer = robot_lab.tf_buffer()
    assert hidden in sess.node.get_node_names()
    buffer.close()
    assert hidden not in sess.node.get_node_names()
    buffer.close()  # a second close is harmless
    node = rclpy.create_node('kernel_static_broadcaster_2', context=sess.context)
    fresh = robot_lab.tf_buffer()
    try:
        assert fresh is not buffer and hidden in sess.node.get_node_names()
        StaticTransformBroadcaster(node).sendTransform(_msg('world', 'lens', 0.0))
        got = fresh.lookup_transform('world', 'lens', rclpy.time.Time(),
                                     timeout=Duration(seconds=10))
        assert got.transform.translation.x == 42.0
    finally:
        node.destroy_node()
        fresh.close()


def test_buffer_server_answers_a_buffer_client(start) -> None:  # type: ignore[no-untyped-def]
    """`ros2 run tf2_ros buffer_server` and tf2_ros.BufferClient over LookupTransform."""
    import threading

    from rclpy.context import Context
    from rclpy.duration import Duration
    from rclpy.executors import SingleThreadedExecutor
    from tf2_ros import BufferClient  # type: ignore[import-untyped]  # the kit's module path

    from robot_lab.tf2.exceptions import LookupException

    start(*STATIC, '--x', '3', '--frame-id', 'world', '--child-frame-id', 'dock')
    start('ros2', 'run', 'tf2_ros', 'buffer_server')
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node('buffer_client_test', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    spinning = threading.Thread(target=executor.spin, daemon=True)
    spinning.start()
    try:
        client = BufferClient(node, 'tf2_buffer_server')
        assert client.action_client.wait_for_server(timeout_sec=20)
        got = client.lookup_transform('world', 'dock', rclpy.time.Time(),
                                      timeout=Duration(seconds=10))
        assert got.transform.translation.x == 3.0
        with pytest.raises(LookupException) as missing:
            client.lookup_transform('world', 'nowhere', rclpy.time.Time())
        assert str(missing.value) == ('"nowhere" passed to lookupTransform argument '
                                      'source_frame does not exist. ')
        assert client.can_transform('world', 'dock', rclpy.time.Time()) is True
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.utilities.try_shutdown(context=context)


# --- the programs ---------------------------------------------------------------------------

def test_static_publisher_echo_and_view_frames(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    listed = cli_ok('pkg', 'executables', 'tf2_ros').splitlines()
    assert {'tf2_ros static_transform_publisher', 'tf2_ros tf2_echo',
            'tf2_ros tf2_monitor'} <= set(listed)
    flags = start(*STATIC, '--x', '1', '--y', '2', '--yaw', '1.5707963267948966',
                  '--frame-id', 'world', '--child-frame-id', 'mystatic')
    old = start(*STATIC, '0', '0', '1', '0', '0', '0', 'mystatic', 'old')
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'world', 'old', '10')
    old.wait_for(r'\[WARN\] \[[0-9.]+\] \[\]: Old-style arguments are deprecated; see --help '
                 r'for new-style arguments')
    flags.wait_for(r"^rotation: \('0\.000000', '0\.000000', '0\.707107', '0\.707107'\)$")
    assert _translation(echo) == (1.0, 2.0, 1.0)
    # both static frames are out: view_frames' 2 s of listening will hear them
    views = start('ros2', 'run', 'tf2_tools', 'view_frames', '-t', '2', '-o',
                  str(tmp_path / 'frames'), cwd=tmp_path)
    echo.wait_for(r'^- Rotation: in RPY \(degree\) \[0\.000, -?0\.000, 90\.000\]$')
    echo.wait_for(r'^  0\.000  0\.000  0\.000  1\.000$')  # the matrix's last row
    lines = echo.lines[echo.lines.index('- Matrix:') + 1:][:4]
    assert lines[0] == '  0.000 -1.000  0.000  1.000' and lines[3] == '  0.000  0.000  0.000  1.000'
    assert re.search(r'^At time 0\.0$', '\n'.join(echo.lines), re.M)
    assert views.popen.wait(timeout=30) == 0, '\n'.join(views.lines)
    gv = (tmp_path / 'frames.gv').read_text()
    assert gv.startswith('digraph G {\n')  # the frames in the order they arrived:
    for edge in ('"world" -> "mystatic"', '"mystatic" -> "old"'):
        assert (f'\n{edge}[label=" Broadcaster: default_authority\\nAverage rate: 10000.0\\n'
                'Buffer length: 0.0\\nMost recent transform: 0.0\\nOldest transform: 0.0\\n'
                '"];\n') in gv
    assert '}->"world";\n}' in gv
    assert (tmp_path / 'frames.pdf').read_bytes().startswith(b'%PDF')


def test_tf2_monitor_and_the_kits_turtle_demo(start) -> None:  # type: ignore[no-untyped-def]
    """`tf2_monitor` and `tf2_monitor world carrot1` against a static publisher and the kit's
    turtle_tf2_py fixed-frame demo (pose broadcasters, a 10 Hz carrot1): after their 10 s of
    gathering, the lines tf2_monitor.cpp prints. Meanwhile the demo's turtle2 reaches carrot1."""
    start(*STATIC, '--x', '1', '--frame-id', 'world', '--child-frame-id', 'dock')
    demo = start('ros2', 'launch', 'turtle_tf2_py', 'turtle_tf2_fixed_frame_demo.launch.py')
    demo.wait_for(r'\[listener\]: Successfully spawned turtle2', timeout=30)
    every = start('ros2', 'run', 'tf2_ros', 'tf2_monitor')
    chain = start('ros2', 'run', 'tf2_ros', 'tf2_monitor', 'world', 'carrot1')
    # the package's other nodes, beside: turtle3's PointStamped source (in the same turtlesim)
    # and the dynamic carrot, its /tf remapped so that it leaves the fixed carrot1 alone
    start('ros2', 'run', 'turtle_tf2_py', 'turtle_tf2_message_broadcaster')
    start('ros2', 'run', 'turtle_tf2_py', 'dynamic_frame_tf2_broadcaster', '--ros-args', '-r',
          '/tf:=/tf_dynamic')
    point = start('ros2', 'topic', 'echo', '--once', '/turtle3/turtle_point_stamped',
                  'geometry_msgs/msg/PointStamped')
    hop = start('ros2', 'topic', 'echo', '--once', '/tf_dynamic', 'tf2_msgs/msg/TFMessage')
    usage = subprocess.run([str(BIN / 'ros2'), 'run', 'tf2_ros', 'tf2_monitor', 'world'],
                           capture_output=True, text=True, timeout=60, check=False)
    assert usage.returncode == 255
    assert 'TF_Monitor: usage: tf2_monitor framea frameb' in usage.stdout + usage.stderr
    # the kit's demo: turtle2 (spawned at (4, 2)) comes within 0.3 m of carrot1
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'turtle2', 'carrot1', '5')
    echo.wait_for(r'^- Translation: \[-?0\.[0-2]\d\d, -?0\.[0-2]\d\d, 0\.000\]$', timeout=40)
    point.wait_for(r'^  frame_id: world$', timeout=30)
    assert 0.0 < float(point.wait_for(r'^  x: (\S+)$')[1]) < 11.1  # inside turtlesim's window
    hop.wait_for(r'^  child_frame_id: carrot1$', timeout=30)
    assert '    frame_id: turtle1' in hop.lines
    assert abs(float(hop.wait_for(r'^      y: (\S+)$')[1])) == pytest.approx(10.0)
    number = r'(-?[0-9.e+-]+)'

    def frame(proc: Proc, name: str) -> tuple[float, float]:
        found = proc.wait_for(rf'^Frame: {name}, published by <no authority available>, '
                              rf'Average Delay: {number}, Max Delay: {number}$', timeout=30)
        return float(found[1]), float(found[2])

    every.wait_for(r'^Gathering data on all frames for 10 seconds\.\.\.$')
    every.wait_for(r'^RESULTS: for all Frames$', timeout=30)
    for moving in ('carrot1', 'turtle1', 'turtle2'):  # stamped now, heard at once
        average, most = frame(every, moving)
        assert 0.0 <= average <= most < 2.0, (moving, average, most)
    average, most = frame(every, 'dock')  # stamped once, when the publisher started
    assert 0.0 < average <= most
    rate = every.wait_for(rf'^Node: <no authority available> {number} Hz, Average Delay: '
                          rf'{number} Max Delay: {number}$')
    assert float(rate[1]) > 10.0  # /tf messages a second: two turtles' poses and the carrot
    lines = every.lines
    assert 'All Broadcasters:' in lines
    assert lines.index('Frames:') < min(i for i, x in enumerate(lines) if x.startswith('Frame:'))

    chain.wait_for(r'^Gathering data on world -> carrot1 for 10 seconds\.\.\.$')
    chain.wait_for(r'^RESULTS: for world to carrot1$', timeout=30)
    chain.wait_for(r'^Chain is: world -> turtle1 -> carrot1$')
    net = chain.wait_for(rf'^Net delay     avg = {number}: max = {number}$')
    assert 0.0 <= float(net[1]) <= float(net[2])
    listed = [x.split(',')[0] for x in chain.lines if x.startswith('Frame:')]
    assert listed[:2] == ['Frame: carrot1', 'Frame: turtle1'], chain.lines
