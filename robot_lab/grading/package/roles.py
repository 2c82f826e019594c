"""Who is the sensor, the controller and the actuator: inferred from the live graph.

Students name packages, nodes, topics and types as they like, so roles come from
behaviour seen by an observer session in the job's domain, never from names:

- sensor: publishes a topic periodically, the measurement a controller subscribes to.
  It may take no input, or close the loop: a sensor that simulates the plant reads the
  commands (or what the actuator reports) and publishes the measurement they lead to.
  Either is the assignment's "a sensor node publishes simulated data"; a node whose input
  comes from outside the loop is not a sensor but a relay;
- controller: subscribes to the sensor's topic and publishes another topic (its commands)
  (whether they follow the readings, robot_lab.grading.package.perturb tests, with the
  sensor paused, so a closed loop's sensor never answers the grader's drive);
- actuator: subscribes to the commands and writes a log line for each one received.

`observe()` watches the graph (every topic with a subscription of its own, `/rosout` for
log lines per node) for a bounded time; `infer_roles()` reads the result.
"""

from __future__ import annotations

import contextlib
import functools
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robot_lab.grading.package.bridge import Bridge
    from robot_lab.rclpy_session import Session

__all__ = ['NodeSeen', 'Observation', 'Roles', 'TopicSeen', 'infer_roles', 'observe']

IGNORED_TOPICS = ('/rosout', '/parameter_events')
_SAMPLES = 3
_SIGNATURES = 200
_VALUES = 100  # message dicts kept per topic (the perturbation imitates the sensor)
_LOG_LINES = 8
_TEXT = 300  # characters of a sample message kept
_STABLE = 3.0  # s the node list must stay the same to stop waiting for missing nodes


@dataclass
class TopicSeen:
    name: str
    types: list[str]
    publishers: list[str] = field(default_factory=list)
    subscribers: list[str] = field(default_factory=list)
    count: int = 0
    first: float = 0.0
    last: float = 0.0
    samples: deque[str] = field(default_factory=lambda: deque(maxlen=_SAMPLES))
    signatures: deque[str] = field(default_factory=lambda: deque(maxlen=_SIGNATURES))
    values: deque[dict[str, Any]] = field(default_factory=lambda: deque(maxlen=_VALUES))

    @property
    def rate(self) -> float:
        span = self.last - self.first
        return (self.count - 1) / span if self.count > 1 and span > 0 else 0.0


@dataclass
class NodeSeen:
    name: str  # full name, '/sensor'
    publishes: list[str] = field(default_factory=list)
    subscribes: list[str] = field(default_factory=list)
    log_count: int = 0
    logs: deque[str] = field(default_factory=lambda: deque(maxlen=_LOG_LINES))


@dataclass
class Observation:
    nodes: dict[str, NodeSeen] = field(default_factory=dict)
    topics: dict[str, TopicSeen] = field(default_factory=dict)
    duration: float = 0.0  # the watch window, after the nodes were up
    faults: list[str] = field(default_factory=list)  # graph queries of the grader that failed

    def log_rate(self, node: str) -> float:
        seen = self.nodes.get(node)
        return seen.log_count / self.duration if seen and self.duration > 0 else 0.0


@dataclass
class Roles:
    sensor: str | None = None
    sensor_topic: str | None = None
    controller: str | None = None
    command_topic: str | None = None
    actuator: str | None = None
    notes: list[str] = field(default_factory=list)


def _logger_node(logger: str, nodes: list[str]) -> str | None:
    """The node a /rosout record's logger name belongs to ('ns.sensor' -> '/ns/sensor')."""
    wanted = '/' + logger.replace('.', '/')
    for node in nodes:
        if wanted == node or wanted.startswith(node + '/'):
            return node
    tail = logger.rsplit('.', 1)[-1]
    return next((n for n in nodes if n.rsplit('/', 1)[-1] == tail), None)


class _Watcher:
    """Subscriptions of the observer session; callbacks only count and keep samples."""

    def __init__(self, sess: Session, bridge: Bridge | None = None) -> None:
        self.sess = sess
        self.bridge = bridge  # reads the types this process does not load (the student's)
        self.obs = Observation()
        self.lock = threading.Lock()
        self.subs: dict[str, Any] = {}
        self.counting = False
        self.unassigned_logs: deque[tuple[str, str]] = deque(maxlen=2000)
        self.unread: dict[str, str] = {}  # node -> why its endpoints could not be read

    def _on_message(self, topic: str, msg: Any) -> None:
        from robot_lab.messages import message_to_dict

        try:
            data: dict[str, Any] | None = message_to_dict(msg)
        except Exception:  # an unusual type: counted, not shown
            data = None
        self._on_data(topic, data)

    def _on_data(self, topic: str, data: dict[str, Any] | None) -> None:
        if not self.counting:
            return
        now = time.monotonic()
        with self.lock:
            seen = self.obs.topics[topic]
            if seen.count == 0:
                seen.first = now
            seen.count += 1
            seen.last = now
        if data is None:
            return
        text = str(data)
        with self.lock:
            seen.samples.append(text[:_TEXT])
            seen.signatures.append(text[:_TEXT])
            seen.values.append(data)

    def _on_log(self, msg: Any) -> None:
        if not self.counting:
            return
        line = f'[{msg.name}] {msg.msg}'[:_TEXT]
        with self.lock:
            node = _logger_node(msg.name, list(self.obs.nodes))
            if node is None:
                self.unassigned_logs.append((msg.name, line))
                return
            self.obs.nodes[node].log_count += 1
            self.obs.nodes[node].logs.append(line)

    def refresh(self) -> list[str]:
        """Re-read the graph: nodes, their endpoints, new topics subscribed; the nodes."""
        from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy

        from robot_lab.graph.discovery import full_node_names
        from robot_lab.messages import message_class

        node = self.sess.node
        names = [n for n in full_node_names(self.sess, include_hidden=False)]
        with self.lock:
            for full in names:
                base = full.rsplit('/', 1)
                namespace, short = (base[0] or '/'), base[1]
                seen = self.obs.nodes.setdefault(full, NodeSeen(full))
                try:
                    seen.publishes = sorted(
                        t for t, _ in node.get_publisher_names_and_types_by_node(short, namespace)
                        if t not in IGNORED_TOPICS)
                    seen.subscribes = sorted(
                        t for t, _ in node.get_subscriber_names_and_types_by_node(short, namespace)
                        if t not in IGNORED_TOPICS)
                    self.unread.pop(full, None)
                except Exception as err:  # gone since listed (it died), or the query failed
                    if type(err).__name__ != 'NodeNameNonExistentError':
                        self.unread[full] = f'{type(err).__name__}: {err}'
                # Log lines that came before the node was discovered.
                for logger, line in list(self.unassigned_logs):
                    if _logger_node(logger, [full]) == full:
                        seen.log_count += 1
                        seen.logs.append(line)
                        self.unassigned_logs.remove((logger, line))
        for topic, types in node.get_topic_names_and_types():
            if topic in IGNORED_TOPICS or topic.startswith('/_'):
                continue
            with self.lock:
                seen_topic = self.obs.topics.setdefault(topic, TopicSeen(topic, list(types)))
                seen_topic.publishers = sorted(
                    n for n in names if topic in self.obs.nodes[n].publishes)
                seen_topic.subscribers = sorted(
                    n for n in names if topic in self.obs.nodes[n].subscribes)
            if topic in self.subs or len(types) != 1:
                continue
            try:
                cls = message_class(types[0])
            except Exception:  # not a type of the kit's: the helper process reads it
                if self.bridge is not None:
                    self.subs[topic] = None
                    self.bridge.subscribe(topic, types[0],
                                          functools.partial(self._on_data, topic))
                continue
            qos = QoSProfile(depth=50, reliability=QoSReliabilityPolicy.BEST_EFFORT)
            if _latched(node, topic):  # as `ros2 topic echo` adapts: else never a sample
                qos = QoSProfile(depth=50, reliability=QoSReliabilityPolicy.RELIABLE,
                                 durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
            self.subs[topic] = node.create_subscription(
                cls, topic, functools.partial(self._on_message, topic), qos)
        return names

    def start_logs(self) -> None:
        from rcl_interfaces.msg import Log
        from rclpy.qos import QoSProfile, QoSReliabilityPolicy

        qos = QoSProfile(depth=100, reliability=QoSReliabilityPolicy.BEST_EFFORT)
        self.subs['/rosout'] = self.sess.node.create_subscription(Log, '/rosout', self._on_log, qos)

    def close(self) -> None:
        for topic, sub in self.subs.items():
            if sub is None and self.bridge is not None:
                self.bridge.unsubscribe(topic)
                continue
            with contextlib.suppress(Exception):
                self.sess.node.destroy_subscription(sub)


def _latched(node: Any, topic: str) -> bool:
    """Whether every publisher of `topic` is reliable and transient-local (a "latched"
    topic: /robot_description, /tf_static, sent once at start-up). A volatile watch never
    gets that one message, and waited _UNMATCHED s for it (measured: 10 s of every
    description package's job)."""
    from rclpy.qos import QoSDurabilityPolicy, QoSReliabilityPolicy

    try:
        infos = node.get_publishers_info_by_topic(topic)
    except Exception:  # a failed query: the usual best-effort, volatile watch
        return False
    return bool(infos) and all(
        i.qos_profile.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL
        and i.qos_profile.reliability == QoSReliabilityPolicy.RELIABLE for i in infos)


# How long the observer waits for each published topic's first sample before it counts.
# A topic whose publishers have matched the observer's subscription can still be waiting
# for discovery: that match is the reader's side, and the writer sends nothing until it has
# matched the reader too; a controller publishes nothing until it has matched its input.
# Taking a matched topic quiet for 2 s as silent, a loaded CI host graded a correct sensor
# and controller as silent (0 messages in the window, both running, the controller's first
# commands at its end). A silent publisher (a fault) costs its student this long.
_UNMATCHED = 10.0
# A node's endpoints are announced one by one after its name, and a lost announcement is
# sent again: a node can be listed with its subscription and not yet its publisher. The
# wait goes on until the endpoints have stood still this long, so that a topic found late
# is waited for too, not first subscribed in the middle of the window. (Without it, the
# wait looked only at the topics known when the nodes came up: a loaded CI host counted a
# correct controller's /cmd_vel from its first refresh inside the window, 0 in 3.5 s.)
_ENDPOINTS_STILL = 1.0


def _unheard(sess: Session, pids: list[int]) -> bool:
    """Whether one of these processes has not been heard with a node yet (False when the
    participants do not say which process they are)."""
    from robot_lab.graph.discovery import processes_unheard

    return bool(processes_unheard(sess, pids))


def _endpoints(watcher: _Watcher) -> tuple[tuple[str, tuple[str, ...], tuple[str, ...]], ...]:
    with watcher.lock:
        return tuple((n.name, tuple(n.publishes), tuple(n.subscribes))
                     for n in watcher.obs.nodes.values())


def _until_samples(watcher: _Watcher) -> float:
    """Refresh the graph until the nodes' endpoints have stood still for _ENDPOINTS_STILL s
    and every published topic has delivered a sample to the observer, or _UNMATCHED has
    passed (its publishers are silent). Returns the seconds waited."""
    start = time.monotonic()
    last, changed = _endpoints(watcher), start
    while True:
        with watcher.lock:
            waiting = [t.name for t in watcher.obs.topics.values()
                       if t.publishers and t.name in watcher.subs and t.count == 0]
        now = time.monotonic()
        if now - start >= _UNMATCHED or (not waiting and now - changed >= _ENDPOINTS_STILL):
            return now - start
        time.sleep(0.1)
        watcher.refresh()
        seen = _endpoints(watcher)
        if seen != last:
            last, changed = seen, time.monotonic()


def observe(sess: Session, expected_nodes: int, startup: float, duration: float,
            alive: Callable[[], bool],
            running: Callable[[], list[int]] = list,
            bridge: Bridge | None = None) -> Observation:
    """Watch the graph: wait (≤ `startup` s) until `expected_nodes` nodes are up, then count
    messages and log lines for `duration` s. `alive()` False ends the wait early; `bridge`
    reads the topics of types this process does not load (robot_lab.grading.package.bridge).

    Fewer nodes than expected (a crashed or hung process) end the wait once the node list
    has stood still for _STABLE s and every process in `running()` (pids) has been heard
    with a node: on a busy host a slow node can come well after a crashed one has gone.
    """
    watcher = _Watcher(sess, bridge)
    watcher.start_logs()
    try:
        deadline = time.monotonic() + startup
        watcher.counting = True
        last: list[str] = []
        changed = time.monotonic()
        while time.monotonic() < deadline:
            names = watcher.refresh()
            if len(names) >= expected_nodes or not alive():
                break
            if names != last:
                last, changed = names, time.monotonic()
            elif (names and time.monotonic() - changed > _STABLE
                  and not _unheard(sess, running())):
                break  # some nodes never come (crashed, hung): grade what is there
            time.sleep(0.2)
        # Count from here: a full window with every subscription in place, i.e. once each
        # published topic has delivered a sample to the observer (or is silent).
        watcher.refresh()
        waited = _until_samples(watcher)
        print(f'[grader] graph and first samples waited for: {waited:.1f} s; topics: '
              + ', '.join(f'{t.name} ({len(t.publishers)} pub)'
                          for t in watcher.obs.topics.values()), flush=True)
        with watcher.lock:
            for topic in watcher.obs.topics.values():
                topic.count, topic.first, topic.last = 0, 0.0, 0.0
            for node in watcher.obs.nodes.values():
                node.log_count = 0
        started = time.monotonic()
        end = started + duration
        while time.monotonic() < end:
            time.sleep(min(0.5, max(0.0, end - time.monotonic())))
            watcher.refresh()
        watcher.counting = False
        watcher.obs.duration = time.monotonic() - started
        watcher.obs.faults = [f"{node}'s topics could not be read: {why}"
                              for node, why in watcher.unread.items()]
        if bridge is not None and (failed := bridge.failed()):
            watcher.obs.faults.append(failed)
        return watcher.obs
    finally:
        watcher.counting = False
        watcher.close()


def _closed_loop_sensor(obs: Observation, min_rate: float) -> tuple[str, str] | None:
    """(topic, node) of a sensor that closes the loop: it publishes a periodic topic that a
    controller subscribes to, and everything it reads from other nodes comes from that
    controller or from a node that subscribes to the controller's output (an actuator).
    Preferred: a loop with an actuator that is neither node, then one whose actuator logs
    (in a ring of three that each publish, which node senses is told by who logs), then
    the busiest topic."""
    publishers = {t: s.publishers for t, s in obs.topics.items()}
    found: list[tuple[bool, int, float, str, str]] = []
    for topic, seen in obs.topics.items():
        if seen.count < 2 or seen.rate < min_rate:
            continue
        for pub in seen.publishers:
            inputs = {t for t in obs.nodes[pub].subscribes
                      if any(p != pub for p in publishers.get(t, []))}
            for name in seen.subscribers:
                controller = obs.nodes.get(name)
                if name == pub or controller is None:
                    continue
                for out in controller.publishes:
                    if out == topic:
                        continue
                    downstream = {name} | {n for n, s in obs.nodes.items() if out in s.subscribes}
                    if not all(set(publishers.get(t, [])) - {pub} <= downstream
                               for t in inputs):
                        continue
                    actuators = downstream - {name, pub}
                    logs = max((obs.nodes[n].log_count for n in actuators), default=0)
                    found.append((bool(actuators), logs, seen.rate, topic, pub))
    if not found:
        return None
    _a, _l, _r, topic, pub = max(found)
    return topic, pub


def infer_roles(obs: Observation, min_rate: float) -> Roles:
    """Sensor, controller and actuator from what the observer saw (see the module doc)."""
    roles = Roles()
    student_pubs = {t: s.publishers for t, s in obs.topics.items() if s.publishers}
    # The sensor: a periodic topic whose publisher takes no input from other student nodes,
    # else one whose only input comes back from its controller's loop.
    candidates = []
    for topic, seen in obs.topics.items():
        if seen.count < 2 or seen.rate < min_rate:
            continue
        for pub in seen.publishers:
            inputs = [t for t in obs.nodes[pub].subscribes
                      if any(p != pub for p in student_pubs.get(t, []))]
            if not inputs:
                controlled = any(set(obs.nodes[n].publishes) - {topic}
                                 for n in seen.subscribers if n != pub and n in obs.nodes)
                candidates.append((controlled, len(seen.subscribers), seen.rate, topic, pub))
    # A loop's sensor comes before an open one that no controller reads (a status topic
    # or a heartbeat beside a closed loop), not before one a controller reads.
    best_open = max(candidates) if candidates else None
    loop = None if best_open and best_open[0] else _closed_loop_sensor(obs, min_rate)
    if loop is not None:
        roles.sensor_topic, roles.sensor = loop
    elif best_open is not None:
        _controlled, _subs, _rate, roles.sensor_topic, roles.sensor = best_open
    else:
        return roles
    # The controller: subscribes to the sensor topic, publishes something else.
    best: tuple[int, int, str, str] | None = None
    for name, node in obs.nodes.items():
        if name == roles.sensor or roles.sensor_topic not in node.subscribes:
            continue
        for topic in node.publishes:
            if topic == roles.sensor_topic:
                continue
            out = obs.topics.get(topic)
            count = out.count if out else 0
            listened = len(out.subscribers) if out else 0
            key = (listened, count, topic, name)
            if best is None or key > best:
                best = key
    if best is None:
        subscribers = [n for n, s in obs.nodes.items()
                       if roles.sensor_topic in s.subscribes and n != roles.sensor]
        if not subscribers:
            roles.notes.append(f'no node subscribes to the sensor topic {roles.sensor_topic}')
        return roles
    _l, _c, roles.command_topic, roles.controller = best
    # The actuator: subscribes to the commands.
    actuators = [n for n, s in obs.nodes.items()
                 if roles.command_topic in s.subscribes
                 and n not in (roles.sensor, roles.controller)]
    if actuators:
        roles.actuator = max(actuators, key=lambda n: obs.nodes[n].log_count)
    return roles
