"""Test-side ROS helpers over the kit's in-process session: listen to topics, set params.

Waiting is always on a real condition (a message arrived, a service answered), bounded by
a deadline; nothing sleeps for a fixed time.
"""

from __future__ import annotations

import re
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from conftest import BIN, Proc

from robot_lab.messages import message_class
from robot_lab.rclpy_session import session
from robot_lab.sim.sample_robot import diffbot_urdf


class Listener:
    """Subscribes to one topic on the session node and keeps (receive time, msg) pairs."""

    def __init__(self, topic: str, type_name: str, depth: int = 100) -> None:
        self.topic = topic
        self.messages: list[tuple[float, Any]] = []
        self._cond = threading.Condition()
        self._session = session()
        self._sub = self._session.node.create_subscription(
            message_class(type_name), topic, self._on_msg, depth
        )

    def _on_msg(self, msg: Any) -> None:
        with self._cond:
            self.messages.append((time.monotonic(), msg))
            self._cond.notify_all()

    def wait_until(self, predicate: Callable[[list[tuple[float, Any]]], bool],
                   timeout: float = 10.0, what: str = 'condition') -> list[tuple[float, Any]]:
        deadline = time.monotonic() + timeout
        with self._cond:
            while not predicate(self.messages):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    tail = [m for _, m in self.messages[-5:]]
                    raise AssertionError(f'{self.topic}: {what} not met within {timeout}s; '
                                         f'{len(self.messages)} messages, last: {tail}')
                self._cond.wait(remaining)
            return list(self.messages)

    def wait_count(self, n: int, timeout: float = 10.0) -> list[tuple[float, Any]]:
        return self.wait_until(lambda ms: len(ms) >= n, timeout, f'{n} messages')

    def clear(self) -> None:
        with self._cond:
            self.messages.clear()

    def close(self) -> None:
        self._session.node.destroy_subscription(self._sub)


def rate_of(messages: list[tuple[float, Any]]) -> float:
    """Messages per second between the first and last receive times."""
    if len(messages) < 2:
        return 0.0
    return (len(messages) - 1) / (messages[-1][0] - messages[0][0])


def _client(srv_type: Any, name: str) -> Any:
    node = session().node
    client = node.create_client(srv_type, name)
    if not client.wait_for_service(timeout_sec=10.0):
        node.destroy_client(client)
        raise AssertionError(f'service {name} not available')
    return client


def _call(client: Any, req: Any, what: str, timeout: float = 10.0) -> Any:
    """The answer to `req`, resent every 2 s: right after discovery a request (or its
    answer) can be lost while the server has not yet matched this client (the kit's own
    parameter calls resend the same way)."""
    from robot_lab.errors import GraphError

    deadline = time.monotonic() + timeout
    while True:
        try:
            return session().wait_future(client.call_async(req), 2.0, what)
        except GraphError:
            if time.monotonic() >= deadline:
                raise


def set_param(node_name: str, name: str, value: Any) -> tuple[bool, str]:
    """SetParameters on `node_name`; returns (successful, reason)."""
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter

    client = _client(SetParameters, f'{node_name}/set_parameters')
    try:
        req = SetParameters.Request()
        req.parameters = [Parameter(name, value=value).to_parameter_msg()]
        res = _call(client, req, 'set_parameters')
        result = res.results[0]
        return bool(result.successful), str(result.reason)
    finally:
        session().node.destroy_client(client)


def get_param(node_name: str, name: str) -> Any:
    from rcl_interfaces.srv import GetParameters
    from rclpy.parameter import parameter_value_to_python

    client = _client(GetParameters, f'{node_name}/get_parameters')
    try:
        req = GetParameters.Request()
        req.names = [name]
        res = _call(client, req, 'get_parameters')
        return parameter_value_to_python(res.values[0])
    finally:
        session().node.destroy_client(client)


# The reference sensor's 10 Hz timer, measured where its messages arrive (ros2 topic hz's
# definition). On a loaded host, late callbacks and periods a starved publisher skips pull a
# window's rate down (9.37 Hz beside a clean-clone CI run with two busy loops), and a late
# first message pushes it up: these tests check the verbs' arithmetic on a real topic;
# bench_graph measures their precision.
TEN_HZ = (7.0, 11.0)
_HZ_WINDOW = re.compile(r'^average rate: (\d+\.\d{3})\n\tmin: (\d+\.\d{3})s '
                        r'max: (\d+\.\d{3})s std dev: \d+\.\d{5}s window: (\d+)$', re.M)


def check_ten_hertz(rate: float, shortest: float, longest: float) -> None:
    """A window's rate is about 10 Hz, and its mean interval between its shortest and
    longest (each printed to the millisecond)."""
    assert TEN_HZ[0] <= rate <= TEN_HZ[1], f'{rate:.3f} Hz'
    assert shortest - 5e-4 <= 1 / rate <= longest + 5e-4, (rate, shortest, longest)


def last_hz_window(out: str) -> tuple[float, float, float, int]:
    """Rate, min, max and window size of the last report `topic hz` printed."""
    windows = _HZ_WINDOW.findall(out)
    assert windows, out
    rate, shortest, longest, size = windows[-1]
    return float(rate), float(shortest), float(longest), int(size)


@contextmanager
def diffbot_launch(folder: Path, launch: str, bridge_yaml: str) -> Iterator[Proc]:
    """`ros2 launch` of a launch file's text, saved in `folder` beside what it reads there:
    the sample diff-drive robot (diffbot.urdf) and parameter_bridge's config (bridge.yaml)."""
    (folder / 'diffbot.urdf').write_text(diffbot_urdf())
    (folder / 'bridge.yaml').write_text(bridge_yaml)
    (folder / 'sim.launch.py').write_text(launch)
    process = Proc([str(BIN / 'ros2'), 'launch', str(folder / 'sim.launch.py')])
    try:
        yield process
    finally:
        process.stop()
