"""tf2 over DDS and the tools the tf2 pages run: tf2_ros_py's listener/broadcaster test as
facts; static_transform_publisher (Jazzy flags, the deprecated positional form), tf2_echo,
view_frames (.gv + .pdf with no Graphviz); and the tutorials' turtle_tf2_py demo, turtle2
following turtle1 on the kit's turtlesim with upstream's unchanged broadcaster and listener.
"""

from __future__ import annotations

import math
import re
import time
from pathlib import Path

import pytest
import rclpy
from conftest import Proc, cli_ok
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


# --- the programs ---------------------------------------------------------------------------

def test_static_publisher_echo_and_view_frames(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    listed = cli_ok('pkg', 'executables', 'tf2_ros').splitlines()
    assert {'tf2_ros static_transform_publisher', 'tf2_ros tf2_echo',
            'tf2_ros tf2_monitor'} <= set(listed)
    flags = start(*STATIC, '--x', '1', '--y', '2', '--yaw', '1.5707963267948966',
                  '--frame-id', 'world', '--child-frame-id', 'mystatic')
    old = start(*STATIC, '0', '0', '1', '0', '0', '0', 'mystatic', 'old')
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'world', 'old', '10')
    views = start('ros2', 'run', 'tf2_tools', 'view_frames', '-t', '2', '-o',
                  str(tmp_path / 'frames'), cwd=tmp_path)
    old.wait_for(r'\[WARN\] \[[0-9.]+\] \[\]: Old-style arguments are deprecated; see --help '
                 r'for new-style arguments')
    flags.wait_for(r"^rotation: \('0\.000000', '0\.000000', '0\.707107', '0\.707107'\)$")
    assert _translation(echo) == (1.0, 2.0, 1.0)
    echo.wait_for(r'^- Rotation: in RPY \(degree\) \[0\.000, -?0\.000, 90\.000\]$')
    lines = echo.lines[echo.lines.index('- Matrix:') + 1:][:4]
    assert lines[0] == '  0.000 -1.000  0.000  1.000' and lines[3] == '  0.000  0.000  0.000  1.000'
    assert re.search(r'^At time 0\.0$', '\n'.join(echo.lines), re.M)
    assert views.popen.wait(timeout=30) == 0, '\n'.join(views.lines)
    gv = (tmp_path / 'frames.gv').read_text()
    assert gv.startswith('digraph G {\n"world" -> "mystatic"[label=" Broadcaster: '
                         'default_authority\\nAverage rate: 10000.0\\n')
    assert '}->"world";\n}' in gv
    assert (tmp_path / 'frames.pdf').read_bytes().startswith(b'%PDF')


def test_turtle_tf2_demo_turtle2_follows_turtle1(start) -> None:  # type: ignore[no-untyped-def]
    """Jazzy's *Introducing tf2*: upstream's turtle_tf2_py (broadcaster and listener files
    unchanged) against the kit's turtlesim; turtle2, spawned at (4, 2), reaches turtle1."""
    launch = start('ros2', 'launch', 'turtle_tf2_py', 'turtle_tf2_demo.launch.py')
    launch.wait_for(r'Successfully spawned turtle2', timeout=30)
    echo = start('ros2', 'run', 'tf2_ros', 'tf2_echo', 'turtle2', 'turtle1', '5')
    # turtle1 seen from turtle2 comes within 0.3 (it started 3.9 away)
    echo.wait_for(r'^- Translation: \[-?0\.[0-2]\d\d, -?0\.[0-2]\d\d, 0\.000\]$', timeout=40)
    pose = start('ros2', 'topic', 'echo', '--once', '/turtle2/pose')
    x = float(pose.wait_for(r'^x: (\S+)$')[1])
    assert x == pytest.approx(5.544, abs=0.35)
