"""Lesson 11's checks (robot_lab.grading.check.tf2), fast and without turtlesim: the right
transform passes, and each fault in what a broadcaster sends is named as soon as it is sure
(a wait would not mend it): parent and child swapped, the wrong parent, a misspelt frame, a
quaternion that is not normalised (tf2 turns it into another rotation) or is all zeros (tf2
drops it), a stamp of 0 looked up at the time now; a lookup made as
the listener starts fails without `timeout=` and says so. The broadcasters are real nodes
in this process's session, on the module's own domain; notebook 11's mistake walk
(tests/test_mistake_path_tf2.py) meets the same messages from a student's package.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.duration import Duration
from rclpy.node import Node

from robot_lab.grading import CheckError, check


@pytest.fixture
def broadcast() -> Iterator[Callable[..., None]]:
    """Broadcast one transform from a node in the session (static: once; else at 20 Hz,
    stamped now unless `stamped` is False); every node is destroyed after the test."""
    from robot_lab.rclpy_session import session
    from robot_lab.tf2.broadcasters import StaticTransformBroadcaster, TransformBroadcaster

    nodes: list[Node] = []

    def start(parent: str, child: str, xyz: tuple[float, float, float] = (0.0, 0.0, 1.0),
              quat: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0),
              static: bool = True, stamped: bool = True) -> None:
        node = rclpy.create_node(f'tf2_checks_{len(nodes)}', context=session().context)
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = parent, child
        v, q = t.transform.translation, t.transform.rotation
        v.x, v.y, v.z = xyz
        q.x, q.y, q.z, q.w = quat
        if static:
            t.header.stamp = node.get_clock().now().to_msg()
            StaticTransformBroadcaster(node).sendTransform(t)
        else:
            sender = TransformBroadcaster(node)

            def tick() -> None:
                if stamped:
                    t.header.stamp = node.get_clock().now().to_msg()
                sender.sendTransform(t)

            node.create_timer(0.05, tick)
        session().add_node(node)
        nodes.append(node)

    yield start
    for node in nodes:
        session().remove_node(node)
        node.destroy_node()


def _fails(call: Callable[[], Any]) -> CheckError:
    started = time.monotonic()
    with pytest.raises(CheckError) as failed:
        call()
    # a fault in what was sent is named once sure, well before the check's 10 s
    assert time.monotonic() - started < 8.0, failed.value
    return failed.value


def test_the_right_static_transform_passes(broadcast: Callable[..., None],
                                           capsys: pytest.CaptureFixture[str]) -> None:
    broadcast('world', 'mystaticturtle', quat=(0.0, 0.0, 0.7071068, 0.7071068))
    check.transform_is('world', 'mystaticturtle', translation=(0.0, 0.0, 1.0), yaw=1.5708)
    assert capsys.readouterr().out == \
        '✓ world → mystaticturtle: translation (0.000, 0.000, 1.000), yaw 1.571\n'


@pytest.mark.parametrize(('sent', 'seen', 'hint'), [
    (('mystaticturtle', 'world'), "the transform goes mystaticturtle → world (header.frame_id "
     "'mystaticturtle', child_frame_id 'world')",
     "header.frame_id is the parent frame ('world')"),
    (('map', 'mystaticturtle'), "'mystaticturtle' has the parent 'map', not 'world'",
     "header.frame_id = 'world'"),
    (('world', 'my_static_turtle'), "no frame 'mystaticturtle' on /tf or /tf_static (they "
     'carry world → my_static_turtle)', "is 'my_static_turtle' meant to be 'mystaticturtle'?"),
])
def test_each_frame_name_fault_is_named(broadcast: Callable[..., None], sent: tuple[str, str],
                                        seen: str, hint: str) -> None:
    broadcast(*sent)
    failed = _fails(lambda: check.transform_is('world', 'mystaticturtle'))
    assert failed.seen == seen and failed.hint.startswith(hint), failed


def test_euler_angles_in_the_quaternion_are_not_normalised(
        broadcast: Callable[..., None]) -> None:
    broadcast('world', 'mystaticturtle', quat=(0.0, 0.0, 1.57, 1.0), static=False)
    failed = _fails(lambda: check.transform_is('world', 'mystaticturtle'))
    # tf2 keeps it, normalised (tf2::Transform's matrix): the frame turns by 2.007, not 1.57
    assert failed.seen == 'world → mystaticturtle has the rotation (0.000, 0.000, 1.570, ' \
                          '1.000), of length 1.861, not 1: tf2 normalises it, and the frame ' \
                          'turns by yaw 2.007', failed
    assert 'quaternion_from_euler' in failed.hint


def test_a_zero_quaternion_is_dropped(broadcast: Callable[..., None]) -> None:
    broadcast('world', 'carrot1', quat=(0.0, 0.0, 0.0, 0.0), static=False)
    failed = _fails(lambda: check.transform_is('world', 'carrot1'))
    assert failed.seen.endswith('tf2 ignores it (TF_NAN_INPUT, TF_DENORMALIZED_QUATERNION)')


def test_a_stamp_of_zero_fails_a_lookup_at_the_time_now(broadcast: Callable[..., None]) -> None:
    broadcast('world', 'turtle1', static=False, stamped=False)
    failed = _fails(lambda: check.transform_is('world', 'turtle1', recent=True))
    assert failed.seen.startswith('its stamp is 0.000 s'), failed
    assert 'self.get_clock().now().to_msg()' in failed.hint


def test_a_lookup_as_the_listener_starts_needs_a_timeout(
        broadcast: Callable[..., None]) -> None:
    broadcast('world', 'turtle1', xyz=(2.0, 3.0, 0.0), static=False)
    broadcast('world', 'turtle2', xyz=(4.0, 2.0, 0.0), static=False)

    def at_once(buffer: Any) -> Any:
        return buffer.lookup_transform('turtle2', 'turtle1', rclpy.time.Time())

    def swapped(buffer: Any) -> Any:
        return buffer.lookup_transform('turtle1', 'turtle2', rclpy.time.Time(),
                                       timeout=Duration(seconds=2.0))

    def waits(buffer: Any) -> Any:
        return buffer.lookup_transform('turtle2', 'turtle1', rclpy.time.Time(),
                                       timeout=Duration(seconds=2.0))

    failed = _fails(lambda: check.lookup_returns(at_once, 'turtle2', 'turtle1'))
    assert failed.seen.startswith('it raised LookupException: ') and 'timeout=' in failed.hint
    failed = _fails(lambda: check.lookup_returns(swapped, 'turtle2', 'turtle1'))
    assert failed.seen.startswith('it returned turtle2 seen from turtle1'), failed
    check.lookup_returns(waits, 'turtle2', 'turtle1')
