"""Services in a bag: their `<service>/_service_event` topics, and replaying their requests.

A service with introspection on publishes `<Srv>_Event` messages (service_msgs'
ServiceEventInfo plus the request or response) on `<service>/_service_event`; `ros2 bag
record --service` records those. `ros2 bag play --publish-service-requests` sends the
recorded requests to the live service instead of republishing the events (rosbag2's
PlayerServiceClient): from the server's REQUEST_RECEIVED events by default, or the
clients' REQUEST_SENT events with `--service-requests-source client_introspection`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Literal

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.task import Future

__all__ = [
    'SERVICE_EVENT',
    'RequestSource',
    'ServiceRequestSender',
    'event_topic',
    'is_service_event',
    'service_name',
]

SERVICE_EVENT = '/_service_event'
RequestSource = Literal['service_introspection', 'client_introspection']
REQUEST_SOURCES: tuple[RequestSource, ...] = ('service_introspection', 'client_introspection')

# service_msgs/msg/ServiceEventInfo event types
REQUEST_SENT, REQUEST_RECEIVED, RESPONSE_SENT, RESPONSE_RECEIVED = 0, 1, 2, 3
RESPONSE_WAIT = 5.0  # seconds the player waits for answers to the requests it sent


def is_service_event(topic: str, msgtype: str) -> bool:
    """rosbag2's rule: a `/_service_event` topic carrying a `<pkg>/srv/<Srv>_Event`."""
    return '/srv/' in msgtype and msgtype.endswith('_Event') and topic.endswith(SERVICE_EVENT)


def event_topic(service: str) -> str:
    """`/add_two_ints` (or `add_two_ints`) -> `/add_two_ints/_service_event`."""
    return (service if service.startswith('/') else '/' + service) + SERVICE_EVENT


def service_name(topic: str) -> str:
    """`/add_two_ints/_service_event` -> `/add_two_ints`."""
    return topic[: -len(SERVICE_EVENT)] if topic.endswith(SERVICE_EVENT) else topic


class ServiceRequestSender:
    """Sends one recorded service's requests to the live service, as rosbag2's player does.

    `send(data)` takes one recorded event's CDR bytes and returns True when it sent a
    request; responses are answered on the session's executor and counted in `answered`.
    """

    def __init__(self, node: Node, topic: str, msgtype: str, source: RequestSource,
                 log: Callable[[str, str], None]) -> None:
        from robot_lab.messages import message_class

        self.service = service_name(topic)
        srv_type = msgtype[: -len('_Event')]
        self._srv = message_class(srv_type)  # raises GraphError for an unknown type
        self._event_cls = self._srv.Event
        self._wanted = REQUEST_RECEIVED if source == 'service_introspection' else REQUEST_SENT
        self._log = log
        self._warned_metadata = False
        self.client = node.create_client(self._srv, self.service)
        self.sent = 0
        self.answered = 0
        self._pending: set[Future] = set()
        self._changed = threading.Condition()

    def send(self, data: bytes) -> bool:
        from rclpy.serialization import deserialize_message

        try:
            event = deserialize_message(data, self._event_cls)
        except Exception as exc:
            self._log('ERROR', f"Failed to deserialize service event message for "
                               f"'{self.service}' service! ({exc})")
            return False
        if int(event.info.event_type) != self._wanted:
            return False  # responses, and requests seen from the other side
        if not self.client.service_is_ready():
            self._log('ERROR', "Service request hasn't been sent. "
                               f"The '{self.service}' service isn't ready !")
            return False
        if not event.request:
            if not self._warned_metadata:
                self._warned_metadata = True
                side = ('on service side' if self._wanted == REQUEST_RECEIVED
                        else 'on client side')
                self._log('WARN', "Can't send service request. The configuration of "
                                  f"introspection for '{self.service}' was metadata only "
                                  f'{side}!')
            return False
        future = self.client.call_async(event.request[0])
        with self._changed:
            self._pending.add(future)
        future.add_done_callback(self._answered)
        self.sent += 1
        return True

    def _answered(self, future: Future) -> None:
        with self._changed:
            self._pending.discard(future)
            if not future.cancelled():
                self.answered += 1
            self._changed.notify_all()

    def wait_for_answers(self, timeout: float = RESPONSE_WAIT) -> bool:
        """True when every sent request was answered within `timeout` seconds."""
        with self._changed:
            if self._changed.wait_for(lambda: not self._pending, timeout):
                return True
            left = len(self._pending)
            for future in list(self._pending):
                future.cancel()  # its done-callback takes it out (the lock is re-entrant)
        self._log('WARN', f"{left} request(s) to '{self.service}' got no response "
                          f'within {timeout:g} s')
        return False
