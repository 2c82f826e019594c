"""`ros2 run tf2_ros buffer_server` and tf2_ros's BufferClient: lookups asked of another
process over the `tf2_msgs/action/LookupTransform` action (tf2_ros/src/buffer_server.cpp,
buffer_server_main.cpp; tf2_ros_py/tf2_ros/buffer_client.py).

The server (node `tf_buffer`, parameter `buffer_size`, default 120 s) answers a goal at once
when the transform is there or the goal's timeout is zero, else waits until it is or the
timeout passes (upstream re-checks every 10 ms; here each new transform wakes the wait).
An error travels in the result's `error` (TF2Error), and the client raises the matching
exception with the server's text.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Sequence
from typing import Any

from rclpy.duration import Duration
from rclpy.time import Time

from robot_lab.tf2.buffer import NO_WAIT, Buffer, BufferInterface
from robot_lab.tf2.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

__all__ = ['BufferClient', 'BufferServer', 'main']

# exception -> TF2Error code, most specific first (TransformException last)
_CODES: tuple[tuple[type[TransformException], str], ...] = (
    (ConnectivityException, 'CONNECTIVITY_ERROR'), (LookupException, 'LOOKUP_ERROR'),
    (ExtrapolationException, 'EXTRAPOLATION_ERROR'),
    (InvalidArgumentException, 'INVALID_ARGUMENT_ERROR'), (TimeoutException, 'TIMEOUT_ERROR'),
    (TransformException, 'TRANSFORM_ERROR'))


class BufferServer:
    """tf2_ros::BufferServer: the LookupTransform action over `buffer`."""

    def __init__(self, buffer: Buffer, node: Any, ns: str = 'tf2_buffer_server') -> None:
        from rclpy.action.server import ActionServer, GoalResponse
        from rclpy.callback_groups import ReentrantCallbackGroup
        from tf2_msgs.action import LookupTransform

        self.buffer = buffer
        self._action = LookupTransform
        self.server = ActionServer(node, LookupTransform, ns, self._execute,
                                   goal_callback=lambda _goal: GoalResponse.ACCEPT,
                                   callback_group=ReentrantCallbackGroup())

    def _can(self, goal: Any) -> bool:
        if not goal.advanced:
            return bool(self.buffer.can_transform_core(goal.target_frame, goal.source_frame,
                                                       goal.source_time)[0])
        return bool(self.buffer.can_transform_full_core(
            goal.target_frame, goal.target_time, goal.source_frame, goal.source_time,
            goal.fixed_frame)[0])

    def _result(self, goal: Any) -> Any:
        result = self._action.Result()
        try:
            if goal.advanced:
                result.transform = self.buffer.lookup_transform_full_core(
                    goal.target_frame, goal.target_time, goal.source_frame, goal.source_time,
                    goal.fixed_frame)
            else:
                result.transform = self.buffer.lookup_transform_core(
                    goal.target_frame, goal.source_frame, goal.source_time)
        except TransformException as exc:
            code = next(name for cls, name in _CODES if isinstance(exc, cls))
            result.error.error = getattr(result.error, code)
            result.error.error_string = str(exc)
        return result

    def _execute(self, handle: Any) -> Any:
        goal = handle.request
        end = time.monotonic() + Duration.from_msg(goal.timeout).nanoseconds / 1e9
        if self._can(goal) or end <= time.monotonic():  # at once: succeeded, even an error
            result = self._result(goal)
            handle.succeed()
            return result
        self.buffer._wait_until(lambda: self._can(goal), lambda: end - time.monotonic())
        if not self._can(goal):
            handle.abort()
            return self._action.Result()
        result = self._result(goal)
        if result.error.error:
            handle.abort()
        else:
            handle.succeed()
        return result


class BufferClient(BufferInterface):
    """tf2_ros.BufferClient(node, ns, check_frequency=10.0, timeout_padding=2 s): lookups
    answered by a buffer_server (the node must be spun by another thread meanwhile)."""

    def __init__(self, node: Any, ns: str, check_frequency: float = 10.0,
                 timeout_padding: Duration | None = None) -> None:
        from rclpy.action.client import ActionClient
        from tf2_msgs.action import LookupTransform

        super().__init__()
        self.node = node
        self._action = LookupTransform
        self.action_client = ActionClient(node, LookupTransform, action_name=ns)
        self.check_frequency = check_frequency
        self.timeout_padding = Duration(seconds=2.0) if timeout_padding is None \
            else timeout_padding

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any,
                         timeout: Duration = NO_WAIT) -> Any:
        import warnings

        from builtin_interfaces.msg import Time as TimeMsg

        if isinstance(time, TimeMsg):
            time = Time.from_msg(time)
            warnings.warn('Passing a builtin_interfaces.msg.Time argument is deprecated, and '
                          'will be removed in the near future. Use rclpy.time.Time instead.',
                          stacklevel=2)
        elif not isinstance(time, Time):
            raise TypeError('Must pass a rclpy.time.Time object.')
        goal = self._action.Goal(target_frame=target_frame, source_frame=source_frame,
                                 source_time=time.to_msg(), timeout=timeout.to_msg(),
                                 advanced=False)
        return self._process_goal(goal)

    def lookup_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                              source_time: Any, fixed_frame: str,
                              timeout: Duration = NO_WAIT) -> Any:
        goal = self._action.Goal(target_frame=target_frame, source_frame=source_frame,
                                 source_time=source_time.to_msg(), timeout=timeout.to_msg(),
                                 target_time=target_time.to_msg(), fixed_frame=fixed_frame,
                                 advanced=True)
        return self._process_goal(goal)

    def can_transform(self, target_frame: str, source_frame: str, time: Any,
                      timeout: Duration = NO_WAIT) -> bool:
        try:
            self.lookup_transform(target_frame, source_frame, time, timeout)
        except TransformException:
            return False
        return True

    def can_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                           source_time: Any, fixed_frame: str,
                           timeout: Duration = NO_WAIT) -> bool:
        try:
            self.lookup_transform_full(target_frame, target_time, source_frame, source_time,
                                       fixed_frame, timeout)
        except TransformException:
            return False
        return True

    def _wait(self, future: Any, timeout: Duration) -> None:
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        padding = (timeout.nanoseconds + self.timeout_padding.nanoseconds) / 1e9
        done.wait(max(padding, 1.0 / self.check_frequency))

    def _process_goal(self, goal: Any) -> Any:
        if not self.action_client.server_is_ready():
            raise TimeoutException('The BufferServer is not ready.')
        timeout = Duration.from_msg(goal.timeout)
        sent = self.action_client.send_goal_async(goal)
        self._wait(sent, timeout)
        if not sent.done():
            raise TimeoutException(
                'The LookupTransform goal sent to the BufferServer did not come back in the '
                'specified time. Something is likely wrong with the server.')
        handle = sent.result()
        if not handle.accepted:
            raise TimeoutException(
                'The LookupTransform goal sent to the BufferServer did not come back with '
                'accepted status. Something is likely wrong with the server.')
        answered = handle.get_result_async()
        self._wait(answered, timeout)
        if not answered.done():
            raise TimeoutException(
                'The LookupTransform goal sent to the BufferServer did not come back in the '
                'specified time. Something is likely wrong with the server.')
        return self._process_result(answered.result().result)

    def _process_result(self, result: Any) -> Any:
        if result is None or result.error is None:
            raise TransformException('The BufferServer returned None for result or '
                                     'result.error!  Something is likely wrong with the '
                                     'server.')
        code = result.error.error
        if code != result.error.NO_ERROR:
            for cls, name in _CODES:
                if code == getattr(result.error, name):
                    raise cls(result.error.error_string)
            raise TransformException(result.error.error_string)
        return result.transform


def main(argv: Sequence[str] | None = None) -> None:
    """The buffer_server program: node `tf_buffer`, a listener, the action server."""
    from robot_lab.nodes.base import run_node
    from robot_lab.tf2.listener import TransformListener
    from robot_lab.tf2.static_publisher import version_line

    full = list(sys.argv if argv is None else argv)
    if '--version' in full[1:]:
        print(version_line('buffer_server'))
        return

    def make() -> Any:
        import rclpy

        node: Any = rclpy.create_node('tf_buffer')
        size = node.declare_parameter('buffer_size', 120.0).value
        buffer = Buffer(cache_time=Duration(seconds=size), node=None)
        node._robot_lab_keep = (buffer, TransformListener(buffer, node),
                                BufferServer(buffer, node, 'tf2_buffer_server'))
        return node

    run_node(make, full, threads=4)  # waiting goals must leave the listener a thread
