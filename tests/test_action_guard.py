"""rclpy as it is: the kit's ActionClient guard (rclpy_session.guard_action_clients) only
where rclpy lacks upstream's lock (ros2/rclpy#1308), and never a lock held while a
student's callback runs: a feedback callback that waits for another goal to be sent from
another thread (a notebook cell, a second node) must see it sent."""

from __future__ import annotations

import contextlib
import inspect
import json
import subprocess
import sys
import threading
from typing import Any

import pytest

from robot_lab.rclpy_session import _guard, action_client_has_lock, guard_action_clients

# A server and a client in one process, each on an executor thread of its own, as in a
# kernel (the session's executor) while a cell or another node sends goals.
SCRIPT = r"""
import json, sys, threading, time
from robot_lab.rclpy_session import guard_action_clients
guard_action_clients()
import rclpy
from rclpy.action import ActionClient, ActionServer
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from test_msgs.action import Fibonacci

rclpy.init()
release = threading.Event()


def execute(goal_handle):
    # Feedback until the client has had one (a first one may go before its reader matched).
    while not release.wait(0.05):
        goal_handle.publish_feedback(Fibonacci.Feedback(sequence=[goal_handle.request.order]))
    goal_handle.succeed()
    return Fibonacci.Result(sequence=[goal_handle.request.order])


server_node = rclpy.create_node('guard_server')
ActionServer(server_node, Fibonacci, 'guard', execute, callback_group=ReentrantCallbackGroup())
client_node = rclpy.create_node('guard_client')
client = ActionClient(client_node, Fibonacci, 'guard')
executors = [MultiThreadedExecutor(num_threads=3), SingleThreadedExecutor()]
spinners = [threading.Thread(target=executor.spin, daemon=True) for executor in executors]
for executor, node, spinner in zip(executors, (server_node, client_node), spinners):
    executor.add_node(node)
    spinner.start()
assert client.wait_for_server(timeout_sec=30), 'no action server'

in_callback, sent, callback_done = threading.Event(), threading.Event(), threading.Event()
seen = {}


def on_feedback(feedback):
    if in_callback.is_set():
        return
    in_callback.set()
    seen['sent_while_in_callback'] = sent.wait(float(sys.argv[1]))
    callback_done.set()


def finished(future):
    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    return done


first = client.send_goal_async(Fibonacci.Goal(order=1), feedback_callback=on_feedback)
assert finished(first).wait(30), 'goal 1 never answered'
assert in_callback.wait(30), 'no feedback'
started = time.monotonic()
second = client.send_goal_async(Fibonacci.Goal(order=2))
seen['send_seconds'] = round(time.monotonic() - started, 3)
sent.set()
callback_done.wait(60)
# More goals from this thread while the client's executor takes answers on its own: each
# is answered (the race the guard closes drops one now and then). Fewer than the goal
# service's depth of 10 wait at once: the server keeps only the last 10 requests.
more = [client.send_goal_async(Fibonacci.Goal(order=n)) for n in range(3, 9)]
release.set()
handles = [first.result()] + [f.result() if finished(f).wait(30) else None for f in [second, *more]]
seen['accepted'] = sum(1 for h in handles if h is not None and h.accepted)
results = [h.get_result_async() for h in handles if h is not None]
seen['results'] = sorted(r.result().result.sequence[0] for r in results if finished(r).wait(30))
print(json.dumps(seen), flush=True)
# Join the spinners before exit: a daemon thread still inside rclpy's C++ when the
# interpreter finalizes is unwound through a noexcept frame, and the process aborts
# ("terminate called without an active exception") after the test's answer was printed.
for executor, spinner in zip(executors, spinners):
    executor.shutdown()
    spinner.join(30)
    assert not spinner.is_alive(), 'an executor kept spinning after shutdown'
server_node.destroy_node()
client_node.destroy_node()
rclpy.shutdown()
"""


def test_a_feedback_callback_holds_no_lock_while_another_goal_is_sent() -> None:
    wait = 5.0  # how long the callback waits for the other goal to be sent
    done = subprocess.run([sys.executable, '-c', SCRIPT, str(wait)], capture_output=True,
                          text=True, timeout=180, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    seen = json.loads(done.stdout.splitlines()[-1])
    assert seen['sent_while_in_callback'], (
        f'send_goal_async waited {seen["send_seconds"]} s for the feedback callback to return')
    assert seen['send_seconds'] < wait
    assert seen['accepted'] == 8
    assert seen['results'] == list(range(1, 9))


class _RacyClient:
    """An ActionClient of rclpy's shape without upstream's lock; `during` runs inside each
    send and take (where a lock must be held) and in execute (where none may be)."""

    def __init__(self, during: Any) -> None:
        self._lock = threading.Lock()
        self.during = during

    def send_goal_async(self, goal: Any) -> None:
        self.during('send')

    def _cancel_goal_async(self, handle: Any) -> None:
        self.during('cancel')

    def _get_result_async(self, handle: Any) -> None:
        self.during('result')

    def take_data(self) -> None:
        self.during('take')

    async def execute(self, taken: Any) -> None:
        self.during('execute')


class _FixedClient(_RacyClient):
    """The same with upstream's lock (#1308)."""

    def send_goal_async(self, goal: Any) -> None:
        with self._lock:
            self.during('send')

    def _cancel_goal_async(self, handle: Any) -> None:
        with self._lock:
            self.during('cancel')

    def _get_result_async(self, handle: Any) -> None:
        with self._lock:
            self.during('result')

    def take_data(self) -> None:
        with self._lock:
            self.during('take')


def _fake_client_class(with_lock: bool) -> type:
    """A fresh subclass (_guard marks and wraps the class it is given)."""
    return type('Client', (_FixedClient if with_lock else _RacyClient,), {})


@pytest.mark.no_ros
def test_an_rclpy_with_upstreams_lock_is_left_as_it_is() -> None:
    fixed = _fake_client_class(with_lock=True)
    assert action_client_has_lock(fixed)
    _guard(fixed)
    assert fixed._robot_lab_guarded and not fixed._robot_lab_wrapped  # type: ignore[attr-defined]
    for name in ('send_goal_async', '_cancel_goal_async', '_get_result_async', 'take_data',
                 'execute'):
        assert getattr(fixed, name) is getattr(_FixedClient, name)


@pytest.mark.no_ros
def test_an_rclpy_without_it_sends_and_takes_under_the_kits_lock() -> None:
    racy = _fake_client_class(with_lock=False)
    assert not action_client_has_lock(racy)
    _guard(racy)
    assert racy._robot_lab_wrapped  # type: ignore[attr-defined]
    held: dict[str, bool] = {}

    def during(step: str) -> None:
        # Whether another thread (a student's, sending a goal) would have to wait now.
        lock = client.__dict__.get('_robot_lab_lock')
        outside = threading.Thread(target=lambda: held.__setitem__(
            step, lock is not None and not _try(lock)))
        outside.start()
        outside.join()

    client = racy(during)
    client.send_goal_async(None)
    client._cancel_goal_async(None)
    client._get_result_async(None)
    client.take_data()
    coroutine = client.execute({})
    with contextlib.suppress(StopIteration):
        coroutine.send(None)
    assert held == {'send': True, 'cancel': True, 'result': True, 'take': True,
                    'execute': False}


def _try(lock: Any) -> bool:
    if lock.acquire(blocking=False):
        lock.release()
        return True
    return False


@pytest.mark.no_ros
def test_this_rclpy_is_wrapped_only_if_it_lacks_the_fix() -> None:
    guard_action_clients()
    import rclpy.action.client

    client: Any = rclpy.action.client.ActionClient
    assert client._robot_lab_guarded
    has_fix = 'with self._lock:' in inspect.getsource(rclpy.action.client)
    assert client._robot_lab_wrapped is not has_fix
    assert not hasattr(client.execute, '__wrapped__')
