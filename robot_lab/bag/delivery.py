"""Getting played messages to their subscribers: matched before the first message, reliable
topics paced by acknowledgements, the last ones acknowledged before the publishers go.

A listener already running, or one that falls behind on a loaded host, would otherwise
lose messages the recorded QoS promised it; these bounded waits are the player's only
dependence on who is listening.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Collection, Iterable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rclpy.publisher import Publisher

    from robot_lab.bag.services import ServiceRequestSender
    from robot_lab.rclpy_session import Session

__all__ = ['flush_publishers', 'room_in_history', 'wait_for_matches']

DISCOVERY_WINDOW = 0.6  # one lease announcement of the kit's Fast DDS profile, and a bit
MATCH_TIMEOUT = 2.0  # longest wait for already-known subscribers to match
# KEEP_ALL publishers: how many messages may wait for acknowledgement at once.
ACK_WINDOW = 100
ACK_POLL = 0.1  # s between looks at `stop()` while a subscriber catches up
FLUSH_TIMEOUT = 30.0  # longest wait at the end for subscribers to acknowledge the rest


def wait_for_matches(
    session: Session,
    node: Any,
    publishers: Collection[Publisher],
    senders: Collection[ServiceRequestSender],
    stopped: Callable[[], bool],
    cond: threading.Condition,
) -> None:
    """Give subscribers the graph already knows the chance to match before message 1
    (`cond` is notified on stop)."""
    from robot_lab.graph.discovery import host_participants_seen

    # Every participant on the host seen, where the host's sockets can be counted: a
    # fixed window let a young player publish before it knew a loaded host's listener
    # (CI: the first 26 messages lost at --rate 4).
    everyone = host_participants_seen(session)
    deadline = time.monotonic() + MATCH_TIMEOUT
    while not stopped() and time.monotonic() < deadline:
        seen = everyone()
        settled = seen if seen is not None else (
            time.monotonic() - getattr(session, 'created', 0.0) >= DISCOVERY_WINDOW)
        matched = all(pub.get_subscription_count() >= _matchable(node, pub)
                      for pub in publishers) and _services_ready(node, senders)
        if settled and matched:
            return
        with cond:
            cond.wait(0.02)


def _matchable(node: Any, pub: Publisher) -> int:
    """How many subscriptions the graph shows on pub's topic that its QoS can match.

    A reliable subscriber never matches a best-effort offer (ROS's rule), so counting
    it would hold the first message for the whole MATCH_TIMEOUT.
    """
    from rclpy.qos import QoSCompatibility, qos_check_compatible

    return sum(
        qos_check_compatible(pub.qos_profile, info.qos_profile)[0]
        != QoSCompatibility.ERROR
        for info in node.get_subscriptions_info_by_topic(pub.topic_name))


def _services_ready(node: Any, senders: Collection[ServiceRequestSender]) -> bool:
    """Every recorded service the graph shows a server for is ready for requests."""
    if not senders:
        return True
    served = {name for name, _types in node.get_service_names_and_types()}
    return all(sender.client.service_is_ready() for sender in senders
               if sender.service in served)


def room_in_history(publisher: Publisher, topic: str, unacked: dict[str, int],
                    stopped: Callable[[], bool]) -> bool:
    """Before a reliable volatile topic's next message: once its history holds `depth`
    messages not yet all acknowledged (the next would overwrite one a subscriber has
    not got), wait until its reliable subscribers have acknowledged them. A subscriber
    that falls behind makes the player fall behind the bag's clock instead of losing
    messages, as the recorded reliable QoS promises. (A transient-local topic keeps
    its recorded depth and is not paced: it promises late joiners the last `depth`.)
    `unacked` counts, per topic, the messages sent since all were acknowledged.
    False if stopped meanwhile."""
    from rclpy.duration import Duration
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy

    qos = publisher.qos_profile
    if (qos.reliability != ReliabilityPolicy.RELIABLE
            or qos.durability != DurabilityPolicy.VOLATILE):
        return True
    window = max(1, qos.depth if qos.history == HistoryPolicy.KEEP_LAST else ACK_WINDOW)
    sent = unacked.get(topic, 0)
    # Past half the window, look (without waiting) whether everything has been
    # acknowledged: the blocking wait below can take a writer heartbeat period.
    if sent >= window // 2 and publisher.wait_for_all_acked(Duration(seconds=0)):
        sent = 0
    if sent >= window:
        # A subscriber that is gone stops counting at its lease's end (2 s).
        while not publisher.wait_for_all_acked(Duration(seconds=ACK_POLL)):
            if stopped():
                return False
        sent = 0
    unacked[topic] = sent + 1
    return True


def flush_publishers(publishers: Iterable[Publisher], stopped: Callable[[], bool]) -> None:
    """Reliable subscribers get the last messages before the publishers go away (a
    subscriber that falls behind on a loaded host needs more than a moment)."""
    from rclpy.duration import Duration
    from rclpy.qos import ReliabilityPolicy

    deadline = time.monotonic() + FLUSH_TIMEOUT
    for pub in publishers:
        if pub.qos_profile.reliability != ReliabilityPolicy.RELIABLE:
            continue  # best effort: nothing is acknowledged
        while (not pub.wait_for_all_acked(Duration(seconds=ACK_POLL))
               and not stopped() and time.monotonic() < deadline):
            pass
