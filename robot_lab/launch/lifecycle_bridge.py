"""The launcher's link to its lifecycle nodes: their transitions in, ChangeState out.

launch_ros gives the launcher a ROS node for this; robot_lab's launcher has no DDS
participant until a plan has a LifecycleNode: then this bridge joins the node's domain
through robot_lab's session (rclpy imported only here, only then), subscribes each
lifecycle node's `transition_event` (reported to the supervisor as StateTransition
events) and calls `change_state` for EmitEvent(ChangeState) and `autostart=True` in
worker threads, so the supervisor's loop never waits on DDS.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from lifecycle_msgs.msg import TransitionEvent

from robot_lab.launch.event_router import EventRouter
from robot_lab.launch.events import StateTransition
from robot_lab.launch.plan import LifecycleRequest, ProcessSpec
from robot_lab.launch.process_record import ProcessRecord, domain_of

if TYPE_CHECKING:
    from rclpy.subscription import Subscription

    from robot_lab.rclpy_session import Session

__all__ = ['LifecycleBridge']

# How long a transition request waits for the node's change_state service (a node on a
# loaded machine may take seconds to start).
SERVICE_WAIT = 30.0
_LABELS = {1: 'configure', 2: 'cleanup', 3: 'activate', 4: 'deactivate', 5: 'shutdown',
           6: 'shutdown', 7: 'shutdown'}


class LifecycleBridge:
    """Created by the supervisor when its first lifecycle node starts."""

    def __init__(self, records: list[ProcessRecord], events: EventRouter,
                 defer: Callable[[Callable[[], None]], None],
                 environment: Callable[[ProcessSpec], dict[str, str]],
                 log: Callable[[str, str], None]) -> None:
        self._records = records  # the supervisor's, kept current by it
        self._events = events
        self._defer = defer  # runs a function on the supervisor's thread
        self._environment = environment
        self._log = log
        self._subscriptions: list[tuple[Session, Subscription]] = []
        self._closed = False

    def _session(self, domain: int) -> Session:
        from robot_lab.rclpy_session import session

        return session(domain)

    def watch(self, node_name: str, domain: int, autostart: bool) -> None:
        """Report the node's transitions from now on; `autostart`: configure + activate."""
        sess = self._session(domain)
        topic = f'{node_name}/transition_event'

        def received(msg: TransitionEvent) -> None:
            self._defer(lambda: self._transitioned(node_name, msg))

        subscription = sess.node.create_subscription(TransitionEvent, topic, received, 10)
        self._subscriptions.append((sess, subscription))
        if autostart:
            self._in_thread(lambda: self._change(node_name, domain, 1) and
                            self._change(node_name, domain, 3), subscription)

    def request_matching(self, request: LifecycleRequest) -> None:
        """EmitEvent(ChangeState): each running lifecycle node the matcher accepts."""
        for record in self._records:
            spec = record.spec
            if spec.lifecycle and spec.node_name and record.state == 'running' and \
                    request.matcher(spec.origin):
                self.request(spec.node_name, domain_of(self._environment(spec)),
                             request.transition_id)

    def _transitioned(self, node_name: str, msg: TransitionEvent) -> None:
        """On the supervisor's thread: a StateTransition event for the node's handlers."""
        record = next((r for r in self._records if r.spec.node_name == node_name), None)
        if record is None:
            return
        origin = record.spec.origin
        self._events.emit('state_transition', origin, lambda: StateTransition(
            origin, msg, msg.transition.label, msg.start_state.label, msg.goal_state.label))

    def request(self, node_name: str, domain: int, transition_id: int) -> None:
        """EmitEvent(ChangeState): take `transition_id`, without blocking the caller."""
        watched = next((s for _, s in self._subscriptions
                        if s.topic_name == f'{node_name}/transition_event'), None)
        self._in_thread(lambda: self._change(node_name, domain, transition_id), watched)

    def _in_thread(self, work: Callable[[], object], subscription: Subscription | None) -> None:
        def run() -> None:
            # the transition events must reach us: wait until our subscription is matched
            waited = threading.Event()
            for _ in range(int(SERVICE_WAIT / 0.05)):
                if self._closed or subscription is None or \
                        subscription.get_publisher_count() > 0:
                    break
                waited.wait(0.05)
            if not self._closed:
                work()

        threading.Thread(target=run, name='robot_lab-lifecycle', daemon=True).start()

    def _change(self, node_name: str, domain: int, transition_id: int) -> bool:
        from robot_lab.errors import RobotLabError
        from robot_lab.graph.services import call_service

        label = _LABELS.get(transition_id, str(transition_id))
        try:
            response = call_service(
                f'{node_name}/change_state', 'lifecycle_msgs/srv/ChangeState',
                {'transition': {'id': transition_id}}, SERVICE_WAIT,
                session=self._session(domain))
        except RobotLabError as err:
            why = err.message
            if not self._closed:
                self._defer(lambda: self._log(
                    'ERROR', f"Failed to make transition '{label}' for LifecycleNode "
                    f"'{node_name}': {why}"))
            return False
        if not response.success and not self._closed:
            self._defer(lambda: self._log(
                'ERROR', f"Failed to make transition '{label}' for LifecycleNode "
                f"'{node_name}'"))
        return bool(response.success)

    def close(self) -> None:
        self._closed = True
        for sess, subscription in self._subscriptions:
            with contextlib.suppress(Exception):  # the session may be gone (process exit)
                sess.node.destroy_subscription(subscription)
        self._subscriptions.clear()
