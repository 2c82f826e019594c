"""Nodes in the graph: `node list`, `node info`, waiting for nodes to come up."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
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
from robot_lab.shared_memory import deaf_note

if TYPE_CHECKING:
    from robot_lab.rclpy_session import Session

__all__ = [
    'NodeInfo',
    'find_node',
    'is_hidden',
    'node_info',
    'node_instances',
    'node_list',
    'wait_for_nodes',
]

NamesAndTypes = list[tuple[str, list[str]]]


def is_hidden(name: str) -> bool:
    """Hidden like ROS: any part of the name starts with `_` (the kit's own node, `_x/y`)."""
    return any(part.startswith('_') for part in name.split('/'))


def names_and_types(query: Callable[[], Any], include_hidden: bool,
                    settle: bool, sess: Session) -> NamesAndTypes:
    """`query()`'s (name, types) pairs sorted, hidden ones dropped unless asked for, after
    discovery has settled when `settle` (topic list -t, service list -t)."""

    def probe() -> NamesAndTypes:
        return [(name, list(types)) for name, types in sorted(query())
                if include_hidden or not is_hidden(name)]

    return settled(sess, probe) if settle else probe()


def split_name(full_name: str) -> tuple[str, str]:
    """`/ns/name` -> (`name`, `/ns`); `/name` -> (`name`, `/`)."""
    namespace, _, name = absolute_name(full_name).rpartition('/')
    return name, namespace or '/'


def node_list(include_hidden: bool = False, *, settle: bool = True,
              timeout: float = 2.0, session: Session | None = None) -> list[str]:
    """Full names of the nodes in the graph, sorted (like `ros2 node list`).

    With `settle` (default) it returns once discovery has had its first window and the
    list has stopped changing, or once every node that running robot_lab launches have
    started is in it, so a list taken right after a launch is not partial.
    """
    sess = get_session(session)
    if not settle:
        return full_node_names(sess, include_hidden)
    # Once every announced node is seen, the list is complete: no settling on top.
    return settled(sess, lambda: full_node_names(sess, include_hidden), timeout=timeout,
                   ready_settle=0.0)


def node_instances(session: Session) -> dict[str, list[int | None]]:
    """Each node name's instances that have endpoints now, as their process ids' low 16 bits.

    Every rclpy and rclcpp node publishes /parameter_events and /rosout. A node whose
    participant has left keeps no endpoints (they go with the participant), so a name
    listed more often than it has publishers is a stale entry (see graph/daemon.py).
    Fast DDS writes the low 16 bits of the process id into GUID prefix bytes 4-5, which
    tells which process an instance lives in (None for other RMWs).
    """
    found: dict[str, list[int | None]] = {}
    for topic in ('/parameter_events', '/rosout'):
        per_topic: dict[str, list[int | None]] = {}
        for info in session.node.get_publishers_info_by_topic(topic):
            gid = bytes(info.endpoint_gid)
            pid = int.from_bytes(gid[4:6], 'little') if gid[:2] == b'\x01\x0f' else None
            name = info.node_namespace.rstrip('/') + '/' + info.node_name
            per_topic.setdefault(name, []).append(pid)
        for name, pids in per_topic.items():
            if len(pids) > len(found.get(name, ())):
                found[name] = pids
    return found


def find_node(name: str, include_hidden: bool = False, timeout: float = LOOKUP_TIMEOUT,
              session: Session | None = None) -> str:
    """The node's full name once discovered; GraphError `Unable to find node` after `timeout`."""
    sess = get_session(session)
    full = absolute_name(name)
    found = wait_until(
        lambda: full if full in full_node_names(sess, include_hidden=True) else None, timeout
    )
    if found is None or (is_hidden(full) and not include_hidden):
        raise GraphError(
            f"Unable to find node '{full}'",
            fix='check the name with `robot-lab node list` (is the node running, in '
            f'ROS_DOMAIN_ID={sess.domain_id}?)',
        )
    return found


def wait_for_nodes(names: Iterable[str], timeout: float = 10.0,
                   session: Session | None = None) -> list[str]:
    """Block until every node in `names` is in the graph; GraphError names the missing ones."""
    sess = get_session(session)
    wanted = [absolute_name(n) for n in names]

    def all_there() -> list[str] | None:
        present = set(full_node_names(sess, include_hidden=True))
        return wanted if all(n in present for n in wanted) else None

    if wait_until(all_there, timeout) is None:
        present = set(full_node_names(sess, include_hidden=True))
        missing = [n for n in wanted if n not in present]
        shown = ', '.join(sorted(present)) or 'no node'
        raise GraphError(
            f'nodes not up within {timeout:g} s: {", ".join(missing)} '
            f'(ROS_DOMAIN_ID={sess.domain_id} shows {shown})',
            fix=deaf_note() or 'check that they were started (and did not die) with '
                               '`robot-lab node list`',
        )
    return wanted


@dataclass
class NodeInfo:
    """What `ros2 node info` shows: a node's endpoints as (name, types) pairs."""

    name: str
    subscribers: NamesAndTypes = field(default_factory=list)
    publishers: NamesAndTypes = field(default_factory=list)
    service_servers: NamesAndTypes = field(default_factory=list)
    service_clients: NamesAndTypes = field(default_factory=list)
    action_servers: NamesAndTypes = field(default_factory=list)
    action_clients: NamesAndTypes = field(default_factory=list)


def _by_node(query: Callable[..., Any], node: Any, name: str, namespace: str,
             include_hidden: bool) -> NamesAndTypes:
    from rclpy.node import NodeNameNonExistentError

    try:
        found = query(node, name, namespace)
    except NodeNameNonExistentError as exc:  # the node left after it was found
        raise GraphError(
            f"Unable to find node '{namespace.rstrip('/')}/{name}' ({exc})",
            fix='check the name with `robot-lab node list`',
        ) from None
    return [(n, list(t)) for n, t in sorted(found) if include_hidden or not is_hidden(n)]


def node_info(name: str, include_hidden: bool = False,
              session: Session | None = None) -> NodeInfo:
    """Subscribers, publishers, services and actions of one node (`ros2 node info`)."""
    from rclpy.action.graph import (
        get_action_client_names_and_types_by_node,
        get_action_server_names_and_types_by_node,
    )
    from rclpy.node import Node

    sess = get_session(session)
    full = find_node(name, include_hidden=True, session=sess)
    base, namespace = split_name(full)
    node = sess.node

    def query(method: Callable[[Any, str, str], Any]) -> NamesAndTypes:
        return _by_node(method, node, base, namespace, include_hidden)

    def probe() -> NodeInfo:
        return NodeInfo(
            name=full,
            subscribers=query(Node.get_subscriber_names_and_types_by_node),
            publishers=query(Node.get_publisher_names_and_types_by_node),
            service_servers=query(Node.get_service_names_and_types_by_node),
            service_clients=query(Node.get_client_names_and_types_by_node),
            action_servers=query(get_action_server_names_and_types_by_node),
            action_clients=query(get_action_client_names_and_types_by_node),
        )

    # A fresh session may have the node but not yet all of its endpoints, or have seen
    # endpoints it cannot yet tie to the node; and a node's services (an action's
    # send_goal, ...) can arrive after its topics: an action whose status topic the node
    # already publishes (a server) or reads (a client) must be listed before we answer.
    attributed = endpoints_attributed(sess)
    suffix = '/_action/status'

    def ready() -> bool | None:
        seen = attributed()
        if seen is False:
            return False
        pubs = _by_node(Node.get_publisher_names_and_types_by_node, node, base, namespace,
                        True)
        subs = _by_node(Node.get_subscriber_names_and_types_by_node, node, base, namespace,
                        True)
        servers = {n for n, _ in _by_node(get_action_server_names_and_types_by_node, node,
                                          base, namespace, True)}
        clients = {n for n, _ in _by_node(get_action_client_names_and_types_by_node, node,
                                          base, namespace, True)}
        if any(n.endswith(suffix) and n[: -len(suffix)] not in servers for n, _ in pubs):
            return False
        if any(n.endswith(suffix) and n[: -len(suffix)] not in clients for n, _ in subs):
            return False
        return seen

    return settled(sess, probe, ready=ready)
