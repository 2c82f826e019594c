"""Actions in the graph: `ros2 action list|type|info|send_goal` as data.

`send_goal` is the notebook's way to run an action: it returns an `ActionGoal` that
collects feedback as it arrives (and calls your `feedback` function for each), so a cell
can start a goal, watch `goal.feedback` grow, and `goal.wait()` for the result. The client
is rclpy's own ActionClient on the kernel's session node.
"""

from __future__ import annotations

import importlib
import threading
import time
import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import (
    LOOKUP_TIMEOUT,
    absolute_name,
    endpoints_attributed,
    full_node_names,
    get_session,
    settled,
    wait_until,
)
from robot_lab.graph.nodes import split_name
from robot_lab.messages import message_from_yaml

if TYPE_CHECKING:
    from robot_lab.rclpy_session import Session

__all__ = [
    'ActionGoal',
    'ActionInfo',
    'action_class',
    'action_client',
    'action_info',
    'action_list',
    'action_type',
    'goal_status_name',
    'send_goal',
]

# action_msgs/msg/GoalStatus codes, named as ros2 action send_goal prints them
_STATUS = {0: 'UNKNOWN', 1: 'ACCEPTED', 2: 'EXECUTING', 3: 'CANCELING', 4: 'SUCCEEDED',
           5: 'CANCELED', 6: 'ABORTED'}


def goal_status_name(status: int) -> str:
    return _STATUS.get(status, 'UNKNOWN')


def action_list(*, settle: bool = True,
                session: Session | None = None) -> list[tuple[str, list[str]]]:
    """(name, types) of every action, sorted by name (`ros2 action list -t`)."""
    from rclpy.action.graph import get_action_names_and_types

    sess = get_session(session)

    def probe() -> list[tuple[str, list[str]]]:
        return [(n, list(t)) for n, t in sorted(get_action_names_and_types(sess.node))]

    return settled(sess, probe) if settle else probe()


def action_type(name: str, timeout: float = LOOKUP_TIMEOUT,
                session: Session | None = None) -> list[str]:
    """The action's types; [] when it is not in the graph within `timeout`."""
    from rclpy.action.graph import get_action_names_and_types

    sess = get_session(session)
    action = absolute_name(name)

    def lookup() -> list[str] | None:
        return next((list(t) for n, t in get_action_names_and_types(sess.node)
                     if n == action), None)

    return wait_until(lookup, timeout) or []


@dataclass
class ActionInfo:
    """What `ros2 action info` shows: the nodes with a client or a server of the action."""

    name: str
    clients: list[tuple[str, list[str]]]
    servers: list[tuple[str, list[str]]]


def action_info(name: str, session: Session | None = None) -> ActionInfo:
    """Clients and servers (node name, types) of one action, after discovery settled."""
    from rclpy.action.graph import (
        get_action_client_names_and_types_by_node,
        get_action_server_names_and_types_by_node,
    )
    from rclpy.impl.implementation_singleton import rclpy_implementation
    from rclpy.node import NodeNameNonExistentError

    RCLError = rclpy_implementation.RCLError  # noqa: N806 - rclpy's class

    sess = get_session(session)
    action = absolute_name(name)

    def by_node(query: Callable[[Any, str, str], Any]) -> list[tuple[str, list[str]]]:
        found = []
        for full in full_node_names(sess, include_hidden=True):
            base, namespace = split_name(full)
            try:
                entries = query(sess.node, base, namespace)
            except NodeNameNonExistentError:  # the node left between the two queries
                continue
            except RCLError:  # what rclpy's action queries raise for that (s14T3)
                if full in full_node_names(sess, include_hidden=True):
                    raise  # still there: a real error
                continue
            found += [(full, list(t)) for n, t in entries if n == action]
        return found

    def probe() -> ActionInfo:
        return ActionInfo(name=action,
                          clients=by_node(get_action_client_names_and_types_by_node),
                          servers=by_node(get_action_server_names_and_types_by_node))

    # A node's endpoints can be seen before they are tied to it: wait for that. Its
    # service endpoints (send_goal, ...) can come later than its topics, so also wait
    # while the status topic has more publishers (one per server) or subscribers (one per
    # client) than nodes found with a server or client: CI once printed `Action
    # servers: 0` for a live server.
    attributed = endpoints_attributed(sess)
    status = action + '/_action/status'

    def ready() -> bool | None:
        seen = attributed()
        if seen is False:
            return False
        info = probe()
        if (sess.node.count_publishers(status) > len(info.servers)
                or sess.node.count_subscribers(status) > len(info.clients)):
            return False
        return seen

    return settled(sess, probe, ready=ready)


def action_class(type_name: str) -> Any:
    """`test_msgs/action/Fibonacci` (or `test_msgs/Fibonacci`) -> the generated class."""
    parts = type_name.strip().split('/')
    if len(parts) == 2:
        parts = [parts[0], 'action', parts[1]]
    try:
        if len(parts) != 3 or not all(parts) or parts[1] != 'action':
            raise ValueError(type_name)
        cls = getattr(importlib.import_module(f'{parts[0]}.{parts[1]}'), parts[2])
        cls.Goal, cls.Result, cls.Feedback  # noqa: B018 - an action has all three
    except (AttributeError, ImportError, ValueError):
        raise GraphError(
            f"The passed action type '{type_name}' is invalid",
            fix='use package/action/Type, e.g. test_msgs/action/Fibonacci '
            '(`robot-lab interface list -a` lists the actions this kit has)',
        ) from None
    return cls


_CLIENTS: weakref.WeakKeyDictionary[Session, dict[tuple[str, str], Any]] = (
    weakref.WeakKeyDictionary()
)


def action_client(name: str, type_name: str, session: Session | None = None) -> Any:
    """The session's rclpy ActionClient for (action, type), made once and kept."""
    from rclpy.action.client import ActionClient
    from rclpy.callback_groups import MutuallyExclusiveCallbackGroup

    sess = get_session(session)
    action = absolute_name(name)
    cls = action_class(type_name)
    cache = _CLIENTS.setdefault(sess, {})
    key = (action, f'{cls.__module__}.{cls.__name__}')
    if key not in cache:
        # Made on the executor thread: adding a waitable while it builds a wait set races.
        cache[key] = sess.run_in_executor(lambda: ActionClient(
            sess.node, cls, action, callback_group=MutuallyExclusiveCallbackGroup()))
    return cache[key]


def _server_heard_client(sess: Session, action: str, cls: Any, timeout: float) -> None:
    """Return once the server has matched the client's feedback and status readers.

    The client hearing the server's publishers is not enough: the server must also have
    heard the client's readers, or feedback published before that goes nowhere (a volatile
    writer sends only to the readers it has matched). A participant announces its readers
    in order and the server matches them in that order; a service client made after the
    action client, answered by the server, shows that the server has matched everything
    announced before it (a server answers only a client whose reader it has matched).
    The request asks for the result of a goal id nobody sent: the server answers at once
    with status UNKNOWN and nothing else happens.
    """
    import uuid

    service = cls.Impl.GetResultService
    probe = sess.run_in_executor(
        lambda: sess.node.create_client(service, f'{action}/_action/get_result'))
    try:
        deadline = time.monotonic() + timeout
        if wait_until(lambda: True if probe.service_is_ready() else None, timeout) is None:
            return  # the goal's own wait reports an absent server
        request = service.Request()
        request.goal_id.uuid = list(uuid.uuid4().bytes)
        sess.wait_future(probe.call_async(request), max(0.1, deadline - time.monotonic()),
                         f'reach action server {action}')
    finally:
        sess.run_in_executor(lambda: sess.node.destroy_client(probe))


class ActionGoal:
    """One goal sent to an action server: its id, feedback so far, and (once done) result.

    `feedback` is a list that grows while the server works (a cell can show its length or
    last item); `wait()` blocks for the result; `cancel()` asks the server to stop.
    """

    def __init__(self, action: str, goal: Any, session: Session) -> None:
        self.action = action
        self.goal = goal
        self.goal_id = ''
        self.accepted = False
        self.feedback: list[Any] = []
        self.status = 'UNKNOWN'
        self.result: Any = None
        self._session = session
        self._handle: Any = None
        self._done = threading.Event()

    @property
    def done(self) -> bool:
        return self._done.is_set()

    def wait(self, timeout: float | None = 30.0) -> Any:
        """The result message once the goal has finished; GraphError after `timeout` s."""
        if not self._done.wait(timeout):
            raise GraphError(
                f'goal {self.goal_id} on {self.action}: no result within {timeout:g} s '
                f'(status {self.status}, {len(self.feedback)} feedback messages so far)',
                fix='wait longer (`goal.wait(timeout=...)`) or `goal.cancel()` it',
            )
        return self.result

    def cancel(self, timeout: float = 5.0) -> bool:
        """Ask the server to cancel the goal; True if it agreed to."""
        if self._handle is None or self.done:
            return False
        response = self._session.wait_future(self._handle.cancel_goal_async(), timeout,
                                             f'cancel goal on {self.action}')
        return bool(response.goals_canceling)

    def _finished(self, future: Any) -> None:
        wrapped = future.result()
        if wrapped is not None:
            self.result = wrapped.result
            self.status = goal_status_name(wrapped.status)
        self._done.set()

    def __repr__(self) -> str:
        return (f'<ActionGoal {self.action} {self.goal_id or "(not sent)"} {self.status}, '
                f'{len(self.feedback)} feedback>')


def send_goal(name: str, type_name: str, goal: str | Mapping[str, Any] | Any = None, *,
              feedback: Callable[[Any], None] | None = None, wait: bool = True,
              timeout: float = 30.0, server_timeout: float = 10.0,
              session: Session | None = None) -> ActionGoal:
    """Send a goal to action `name` and (with `wait`) wait for its result.

    `goal` is YAML text (`'{order: 5}'`, as `ros2 action send_goal` takes), a dict or a
    Goal message. `feedback(msg)` is called with each feedback message (from the session's
    thread), which are also collected in the returned goal's `.feedback`. With
    `wait=False` it returns as soon as the server accepted the goal. Feedback and result
    come on different DDS topics: a feedback message sent just before the result can
    arrive after it and is then dropped by rclpy (ros2cli's `--feedback` too), so the last
    one or two of a fast goal may be missing; the result is never lost.

        >>> g = robot_lab.send_goal('/fibonacci', 'test_msgs/action/Fibonacci', {'order': 5})
        >>> g.status, list(g.result.sequence)
        ('SUCCEEDED', [0, 1, 1, 2, 3, 5])
    """
    sess = get_session(session)
    action = absolute_name(name)
    cls = action_class(type_name)
    message = goal if isinstance(goal, cls.Goal) else message_from_yaml(cls.Goal, goal)
    client = action_client(action, type_name, session=sess)
    # The feedback and status topics too: a goal sent before the client heard the server's
    # feedback publisher loses the first feedback (ros2cli's `--feedback` can print none).
    topics = [f'{action}/_action/feedback', f'{action}/_action/status']

    def _ready() -> bool | None:
        return True if client.server_is_ready() and all(
            sess.node.count_publishers(t) > 0 for t in topics) else None

    if wait_until(_ready, server_timeout) is None:
        raise GraphError(
            f"action server '{action}' not available within {server_timeout:g} s",
            fix='is it running? `robot-lab action list -t` shows the actions',
        )
    _server_heard_client(sess, action, cls, server_timeout)
    sent = ActionGoal(action, message, sess)

    def on_feedback(msg: Any) -> None:
        sent.feedback.append(msg.feedback)
        if feedback is not None:
            feedback(msg.feedback)

    handle = sess.wait_future(client.send_goal_async(message, feedback_callback=on_feedback),
                              server_timeout, f'send goal to {action}')
    sent._handle = handle
    sent.goal_id = bytes(handle.goal_id.uuid).hex()
    sent.accepted = bool(handle.accepted)
    if not sent.accepted:
        sent.status = 'REJECTED'
        sent._done.set()
        return sent
    sent.status = 'ACCEPTED'
    handle.get_result_async().add_done_callback(sent._finished)
    if wait:
        deadline = time.monotonic() + timeout
        sent.wait(max(0.0, deadline - time.monotonic()))
    return sent
