"""How long to wait for the ROS graph: DDS discovery is not instant.

A fresh participant learns about the others in bursts: the ones that answer its initial
announcements at once, the rest only at their next lease announcement (0.2 s with the
kit's Fast DDS profile, see robot_lab/data/fastdds_profile.xml). So a query that must be
complete (`node list`) waits until the session is older than one announcement period and
the answer has stopped changing; a query for one thing (`param get /sensor …`) polls
until it appears, bounded by a deadline, before calling it unknown.

When robot_lab launches are running, their launchers say which nodes they have up
(robot_lab/graph/expected.py); once all of those are seen, a complete answer is ready
without waiting out the window.

A young session answers on conditions, not on its age alone. With
ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST every participant of the domain on this host has
bound its discovery port, so the kernel's socket table says how many there are
(`participants_on_host`); the session is complete once it has seen that many
participants with named endpoints, and every node it lists has its endpoints (a node's
name arrives before its topics, services and actions). On a loaded host the others'
answers can come seconds apart, which no fixed window covers. A count alone can be
fooled while commands come and go (a participant heard just before it exits stands in
for one not heard yet), so where the socket's owner can be read, the session also needs
that process itself: Fast DDS writes the low 16 bits of its pid into each participant's
GUID prefix (bits two processes can share where pid_max exceeds 65536, so each heard
participant vouches for one port only: host_sockets.unheard_ports). Where the count
cannot be read (another RMW, custom ports), the session falls back to a timing rule: the
others must have answered at all, and a full announcement burst has passed since.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar
from weakref import WeakKeyDictionary

from robot_lab.env import switched_on
from robot_lab.graph.host_sockets import (
    discovery_ports,
    socket_drops,
    unheard_ports,
    unheard_processes,
)
from robot_lab.graph.settler import HostPorts, Rules, RunClock, Settler
from robot_lab.linux import procfs

if TYPE_CHECKING:
    from robot_lab.rclpy_session import Session

__all__ = [
    'LOOKUP_TIMEOUT',
    'RULES',
    'HostCount',
    'absolute_name',
    'endpoints_attributed',
    'full_node_names',
    'get_session',
    'heard_from_others',
    'host_participants_seen',
    'launched_nodes_seen',
    'names_pending',
    'participants_on_host',
    'participants_seen',
    'processes_unheard',
    'settled',
    'socket_drops',
    'wait_until',
]

T = TypeVar('T')

# The waits of settling (settler.Rules says why each is as long as it is). One object, so
# a test replaces it whole: monkeypatch.setattr(discovery, 'RULES', replace(RULES, ...)).
RULES = Rules()
# How long a lookup of a named node/topic waits for discovery before calling it unknown.
LOOKUP_TIMEOUT = 2.5
# Set to 1 to have every settled answer print how it was reached on stderr (why it
# answered, the session's age, the time waited, the host's participants and those seen,
# and at a deadline the processes holding ports not heard); set to a file's path to have
# the lines appended there instead (a kernel's stderr is a notebook cell's output).
DEBUG_VARIABLE = 'ROBOT_LAB_DEBUG_DISCOVERY'
# rmw_dds_common's name for an endpoint whose node has not been announced (yet).
UNKNOWN_NODE = '_NODE_NAME_UNKNOWN_'


def get_session(session: Session | None) -> Session:
    """The session to use: the one given, or the process's session for ROS_DOMAIN_ID."""
    if session is not None:
        return session
    from robot_lab.rclpy_session import session as process_session

    return process_session()


def absolute_name(name: str) -> str:
    """`sensor` -> `/sensor` (ros2cli accepts both for node and topic names)."""
    name = name.strip()
    return name if name.startswith('/') else '/' + name


def wait_until(probe: Callable[[], T | None], timeout: float) -> T | None:
    """Poll `probe` until it returns something other than None, or `timeout` passes (in
    `RunClock` time)."""
    clock = RunClock(RULES.max_poll_gap)
    while True:
        value = probe()
        if value is not None:
            return value
        if clock() >= timeout:
            return None
        time.sleep(RULES.poll)


def full_node_names(session: Session, include_hidden: bool) -> list[str]:
    """`/ns/name` of every node the session sees now, sorted (no waiting)."""
    names = []
    for name, namespace in session.node.get_node_names_and_namespaces():
        if not name or (not include_hidden and name.startswith('_')):
            continue
        names.append(namespace.rstrip('/') + '/' + name)
    return sorted(names)


def launched_nodes_seen(session: Session) -> Callable[[], bool | None]:
    """A probe for `settled`: None when no launch announces nodes on this graph, else
    whether every node the running launches have up is in the session's graph."""
    from robot_lab.graph.expected import expected_nodes, graph_dir

    directory = graph_dir({**os.environ, 'ROS_DOMAIN_ID': str(session.domain_id)})

    def seen() -> bool | None:
        expected = expected_nodes(directory)
        if expected is None:
            return False  # a launch is starting: its nodes are coming
        if not expected:
            return None
        return expected <= set(full_node_names(session, include_hidden=True))

    return seen


def endpoints_attributed(session: Session,
                         topic: str | None = None) -> Callable[[], bool | None]:
    """A probe for `settled` before per-node queries: False while discovery has an
    endpoint (of `topic`, or of any topic) it cannot yet tie to a node (a node's endpoints
    are mapped to it by messages of their own, which can come after the node's name), else
    as `launched_nodes_seen`."""
    launched = launched_nodes_seen(session)
    node = session.node

    def unattributed() -> bool:
        topics = [topic] if topic else [t for t, _ in node.get_topic_names_and_types()]
        for topic_name in topics:
            for info in (*node.get_publishers_info_by_topic(topic_name),
                         *node.get_subscriptions_info_by_topic(topic_name)):
                if info.node_name == UNKNOWN_NODE:
                    return True
        return False

    def ready() -> bool | None:
        seen = launched()
        return False if seen is False or unattributed() else seen

    return ready


def names_pending(session: Session) -> bool:
    """True while a node's /rosout or /parameter_events writer is in the graph without its
    node's name: every rclpy and rclcpp node has both, and rmw ties them to their node by
    the node's own `ros_discovery_info` message, which can come seconds later."""
    node = session.node
    return any(info.node_name == UNKNOWN_NODE
               for topic in ('/rosout', '/parameter_events')
               for info in node.get_publishers_info_by_topic(topic))


def participants_on_host(domain_id: int) -> int | None:
    """How many DDS participants of `domain_id` run on this host (this network namespace),
    this process's included: each has bound its discovery port. None when that cannot be
    told: no socket table, or this process's own port is not among those found (another
    RMW, a profile with other ports), so the count would mean nothing."""
    ports = _host_ports(domain_id)
    return None if ports is None else len(ports)


# The host's discovery ports, once this process's own is among them (see HostPorts).
_host_ports = HostPorts(lambda domain: discovery_ports(domain),
                        lambda: procfs.own_socket_inodes())


def participants_seen(session: Session) -> tuple[int, set[str]]:
    """How many participants (this one included) the session has seen with a named node,
    and the nodes that have endpoints: every rclpy and rclcpp node publishes
    /parameter_events (and most /rosout), and an endpoint's GUID starts with its
    participant's 12-byte prefix."""
    prefixes, named = _named_participants(session)
    return len(prefixes), named


def _named_participants(session: Session) -> tuple[set[bytes], set[str]]:
    node = session.node
    prefixes = set()
    named = set()
    for topic in ('/parameter_events', '/rosout'):
        for info in node.get_publishers_info_by_topic(topic):
            if info.node_name and info.node_name != UNKNOWN_NODE:
                prefixes.add(bytes(info.endpoint_gid)[:12])
                named.add(info.node_namespace.rstrip('/') + '/' + info.node_name)
    return prefixes, named


_EPROSIMA = b'\x01\x0f'  # a GUID prefix's vendor id: Fast DDS
_settlers: WeakKeyDictionary[Session, Settler] = WeakKeyDictionary()
_settlers_lock = threading.Lock()


def settler_of(session: Session) -> Settler:
    """The session's settler (made at its first query; it lives as long as the session)."""
    with _settlers_lock:
        try:
            found = _settlers.get(session)
            if found is None:
                found = _settlers[session] = Settler()
        except TypeError:  # a stand-in session without weak references: one per query
            found = Settler()
        return found


def processes_unheard(session: Session, pids: list[int]) -> list[int] | None:
    """The processes among `pids` whose participant the session has not heard with a named
    node yet (host_sockets.unheard_processes: one heard participant per process, matched
    by whole pids where the host's ports say who holds them). None when a participant is
    another vendor's, whose GUID prefix says nothing of its process."""
    heard = _participant_pids(_named_participants(session)[0])
    if heard is None:
        return None
    return unheard_processes(pids, heard, _host_ports(session.domain_id))


def _participant_pids(prefixes: set[bytes]) -> list[int] | None:
    """The pid bits of each participant (GUID prefix), one entry per participant; None
    unless all are Fast DDS's."""
    if not all(p[:2] == _EPROSIMA for p in prefixes):
        return None
    return [int.from_bytes(p[4:6], 'little') for p in prefixes]


class HostCount:
    """A probe: True once the session has seen every participant of its domain on this
    host (see `participants_on_host`), each with a named node, and every node it lists
    has its endpoints (or has been listed without them for RULES.bare_node_wait); None
    when the host's count cannot be read. It keeps what its last call counted, for the
    note an incomplete answer gets."""

    def __init__(self, session: Session) -> None:
        self.session = session
        self.ports: int | None = None  # participants on the host at the last call
        self.seen = 0  # of them heard with a named node
        self.unheard_process = False  # the last call found a port whose process is unheard

    def __call__(self) -> bool | None:
        ports = _host_ports(self.session.domain_id)  # one read of the socket table per poll
        self.ports = None if ports is None else len(ports)
        self.unheard_process = False
        if ports is None:
            return None
        prefixes, with_endpoints = _named_participants(self.session)
        self.seen = len(prefixes)
        if len(prefixes) < len(ports):
            return False
        heard = _participant_pids(prefixes)
        if heard is not None and unheard_ports(ports, heard):
            self.unheard_process = True  # the count includes one that left, or a process
            return False  # not heard yet
        bare = set(full_node_names(self.session, include_hidden=True)) - with_endpoints
        # kept per session: a kernel's next query does not wait for the same node again
        return settler_of(self.session).bare_long_enough(bare, RULES.bare_node_wait)

    def unheard(self) -> list[str]:
        """`pid:command` of each process holding a discovery port of the domain whose
        participant the session has not heard with a named node, and each node listed
        without its endpoints (for the debug line)."""
        ports = _host_ports(self.session.domain_id)
        prefixes, with_endpoints = _named_participants(self.session)
        ports = ports or {}
        holders = procfs.socket_holders(ports.values())
        found = []
        for port in unheard_ports(ports, _participant_pids(prefixes) or [], holders):
            found += [f'{pid}:{_command(pid)}' for pid in sorted(holders[ports[port]])]
        found += [f'{name} (no endpoints)' for name in
                  full_node_names(self.session, include_hidden=True)
                  if name not in with_endpoints]
        return found

    def say_unheard(self, waited: float) -> None:
        """One line on stderr when an answer leaves out participants the host shows: the
        user then knows the list may be short, and why."""
        missing = 0 if self.ports is None else self.ports - self.seen
        if missing <= 0 and not self.unheard_process:
            return  # everyone heard: a node without endpoints is no missing participant
        what = (f'{missing} of the {self.ports} DDS participants' if missing > 0
                else 'a process holding a DDS port')
        print(f'robot-lab: {what} of ROS_DOMAIN_ID={self.session.domain_id} on this host '
              f'not heard with a node within {waited:.0f} s: this answer may be incomplete '
              '(a busy host, or a process without a node yet); run the command again',
              file=sys.stderr)


def _command(pid: int) -> str:
    """The start of the command line of process `pid`."""
    try:
        return ' '.join(procfs.command_line(pid)).strip()[:120] or '?'
    except OSError:
        return '?'


def _debug(line: str) -> None:
    """One line of ROBOT_LAB_DEBUG_DISCOVERY: on stderr, or appended to its file."""
    where = os.environ.get(DEBUG_VARIABLE, '')
    text = f'robot-lab discovery: pid={os.getpid()} {line}'
    if '/' not in where:
        print(text, file=sys.stderr)
        return
    with contextlib.suppress(OSError), open(where, 'a', encoding='utf-8') as out:
        out.write(text + '\n')  # a debugging aid never breaks the answer


def host_participants_seen(session: Session) -> Callable[[], bool | None]:
    """The `HostCount` probe of `session` (`settled` asks for it here, so a test can
    stand in for it)."""
    return HostCount(session)


def heard_from_others(session: Session) -> Callable[[], bool]:
    """A probe: True once the session's graph holds a node other than its own and every
    non-hidden node it lists has its /rosout publisher (a node's endpoints are announced
    after its name, so a node without them is still arriving)."""
    node = session.node

    def heard() -> bool:
        own = node.get_namespace().rstrip('/') + '/' + node.get_name()
        names = [n for n in full_node_names(session, include_hidden=True) if n != own]
        if not names:
            return False
        with_rosout = {
            (info.node_namespace.rstrip('/') + '/' + info.node_name)
            for info in node.get_publishers_info_by_topic('/rosout')
        }
        return all(n in with_rosout for n in names if not n.rsplit('/', 1)[-1].startswith('_'))

    return heard


def settled(session: Session, probe: Callable[[], T], timeout: float = 2.0,
            settle: float | None = None,
            ready: Callable[[], bool | None] | None = None,
            ready_settle: float | None = None) -> T:
    """`probe()` once discovery is complete (every participant on the host seen, see
    `host_participants_seen`; else the `answer_burst` rule) and the answer stopped changing.
    Bounded by `timeout`, extended while participants the host shows are still unseen.

    `ready` (default: `launched_nodes_seen(session)`) can shorten the settling: True
    means everything known to be coming has been seen; False means more is coming, so the
    wait may extend to RULES.expected_timeout (names_timeout while names_pending); once
    True, the answer need only be stable for `ready_settle` (default RULES.warm_settle;
    `settle` defaults to RULES.settle). A young session whose sockets dropped datagrams
    also waits RULES.resend_wait after the last drop. Bounded: on a graph that keeps
    changing it returns the latest answer.
    """
    if ready is None:
        ready = launched_nodes_seen(session)
    rules = RULES
    began = time.monotonic()
    complete = host_participants_seen(session)
    outcome = settler_of(session).settle(
        probe, created=session.created, rules=rules, timeout=timeout,
        settle=rules.settle if settle is None else settle, ready=ready,
        ready_settle=rules.warm_settle if ready_settle is None else ready_settle,
        complete=complete, heard=heard_from_others(session),
        pending=lambda: names_pending(session), drops=lambda: socket_drops())
    counted = complete if isinstance(complete, HostCount) else None
    if outcome.everyone is False and not outcome.complete and counted is not None:
        counted.say_unheard(outcome.waited)
    if switched_on(DEBUG_VARIABLE):
        _debug(f'{"complete" if outcome.complete else "deadline"} young={outcome.young} '
               f'age={began - session.created:.2f} waited={outcome.waited:.2f} '
               f'wall={time.monotonic() - began:.2f} everyone={outcome.everyone} '
               f'expected={outcome.expectation} ports={counted and counted.ports} '
               f'seen={counted and counted.seen} dropped={outcome.lost}'
               + ('' if outcome.complete or counted is None else
                  f' unheard={counted.unheard()}'))
    return outcome.value
