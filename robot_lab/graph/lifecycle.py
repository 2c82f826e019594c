"""Lifecycle (managed) nodes in the graph: `ros2 lifecycle nodes|get|list|set` as data.

A lifecycle node offers `<node>/get_state`, `<node>/change_state`,
`<node>/get_available_transitions` and `<node>/get_transition_graph` (lifecycle_msgs,
a PyPI wheel); ros2lifecycle finds them by the `get_state` service's type. Every call
waits at most `timeout` s and says what to check when nothing answers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import LOOKUP_TIMEOUT, absolute_name, get_session, wait_until
from robot_lab.graph.nodes import node_list
from robot_lab.graph.services import call_service, service_list_typed

if TYPE_CHECKING:
    from lifecycle_msgs.msg import TransitionDescription

    from robot_lab.rclpy_session import Session

__all__ = [
    'LifecycleTransition',
    'lifecycle_change_state',
    'lifecycle_nodes',
    'lifecycle_state',
    'lifecycle_transitions',
]

_GET_STATE = 'lifecycle_msgs/srv/GetState'


@dataclass(frozen=True)
class LifecycleTransition:
    """One transition a node offers: `configure [1]`, from `unconfigured` to `configuring`."""

    label: str
    id: int
    start: str
    goal: str


def lifecycle_nodes(include_hidden: bool = False, *,
                    session: Session | None = None) -> list[str]:
    """Full names of the nodes that have a lifecycle, sorted (`ros2 lifecycle nodes`)."""
    sess = get_session(session)
    nodes = node_list(include_hidden, session=sess)
    services = dict(service_list_typed(True, session=sess))
    return sorted(n for n in nodes if _GET_STATE in services.get(f'{n}/get_state', []))


def _has_lifecycle(node: str, session: Session) -> bool | None:
    services = dict(session.node.get_service_names_and_types())
    return True if _GET_STATE in services.get(f'{node}/get_state', []) else None


def _lifecycle_node(name: str, session: Session, timeout: float) -> str:
    node = absolute_name(name)
    # a node's services may be discovered a moment after the node itself: wait for them
    found = _has_lifecycle(node, session) or wait_until(
        lambda: _has_lifecycle(node, session), min(timeout, LOOKUP_TIMEOUT))
    if not found:
        raise GraphError('Node not found',
                         fix=f'is {node} running, and is it a lifecycle node? '
                         '`robot-lab lifecycle nodes` lists them')
    return node


def lifecycle_state(name: str, timeout: float = 10.0, *,
                    session: Session | None = None) -> tuple[str, int]:
    """(label, id) of the node's current state, e.g. ('unconfigured', 1)."""
    sess = get_session(session)
    node = _lifecycle_node(name, sess, timeout)
    response = call_service(f'{node}/get_state', _GET_STATE, {}, timeout, session=sess)
    return str(response.current_state.label), int(response.current_state.id)


def lifecycle_transitions(name: str, every: bool = False, timeout: float = 10.0, *,
                          session: Session | None = None) -> list[LifecycleTransition]:
    """The transitions available now (`every`: the whole transition graph)."""
    sess = get_session(session)
    node = _lifecycle_node(name, sess, timeout)
    service = 'get_transition_graph' if every else 'get_available_transitions'
    response = call_service(f'{node}/{service}', 'lifecycle_msgs/srv/GetAvailableTransitions',
                            {}, timeout, session=sess)
    return [_transition(t) for t in response.available_transitions]


def _transition(description: TransitionDescription) -> LifecycleTransition:
    return LifecycleTransition(str(description.transition.label), int(description.transition.id),
                               str(description.start_state.label),
                               str(description.goal_state.label))


def lifecycle_change_state(name: str, transition: str | int, timeout: float = 10.0, *,
                           session: Session | None = None) -> bool:
    """Ask the node to take `transition` (a label such as 'configure', or its id).

    True when the node reports success; GraphError when the transition is not available
    now (the message lists the ones that are, as ros2lifecycle does).
    """
    sess = get_session(session)
    node = _lifecycle_node(name, sess, timeout)
    available = lifecycle_transitions(node, timeout=timeout, session=sess)
    chosen = next((t for t in available if t.label == str(transition)), None) or next(
        (t for t in available if str(t.id) == str(transition)), None)
    if chosen is None:
        raise GraphError('Unknown transition requested, available ones are:' + ''.join(
            f'\n- {t.label} [{t.id}]' for t in available))
    response = call_service(f'{node}/change_state', 'lifecycle_msgs/srv/ChangeState',
                            {'transition': {'id': chosen.id, 'label': chosen.label}},
                            timeout, session=sess)
    return bool(response.success)
