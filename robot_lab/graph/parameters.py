"""A running node's parameters over its parameter services (rcl_interfaces/srv/*).

Every call waits for the service with a deadline and for the answer with a timeout, so a
node that dies mid-call gives a GraphError, never a hang. Clients are made once per
session and target node (a new client has to be discovered before it can call).
"""

from __future__ import annotations

import os
import threading
import time
import weakref
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import absolute_name, get_session, wait_until
from robot_lab.graph.nodes import find_node, node_list

if TYPE_CHECKING:
    from rclpy.client import Client

    from robot_lab.rclpy_session import Session

__all__ = [
    'ParamDescription',
    'SetResult',
    'answer',
    'call_parameter_service',
    'load_sections',
    'param_delete',
    'param_describe',
    'param_dump',
    'param_get',
    'param_get_text',
    'param_list',
    'param_load',
    'param_set',
    'set_parameters',
    'type_label',
]

CALL_TIMEOUT = 5.0
# How long a param verb waits for its node to be discovered: ros2param's 5 s, so a node
# that a cold command has not seen yet is not reported as "Node not found".
NODE_TIMEOUT = 5.0

# ParameterType value -> ros2param's type string
_TYPE_STRINGS = {
    0: 'not set', 1: 'boolean', 2: 'integer', 3: 'double', 4: 'string', 5: 'byte array',
    6: 'boolean array', 7: 'integer array', 8: 'double array', 9: 'string array',
}

_CLIENTS: weakref.WeakKeyDictionary[Session, dict[tuple[str, str], Client]] = (
    weakref.WeakKeyDictionary()
)


def _client(sess: Session, node: str, service: str, srv_type: type) -> Client:
    cache = _CLIENTS.setdefault(sess, {})
    key = (node, service)
    if key not in cache:
        cache[key] = sess.node.create_client(srv_type, f'{node}/{service}')
    return cache[key]


def _target(sess: Session, node: str) -> str:
    """The node's full name, waiting briefly for discovery (ros2cli: `Node not found`)."""
    try:
        return find_node(node, include_hidden=True, timeout=NODE_TIMEOUT, session=sess)
    except GraphError:
        raise GraphError(
            f"Node not found: '{absolute_name(node)}'",
            fix='check the name with `robot-lab node list` (is the node running, in '
            f'ROS_DOMAIN_ID={sess.domain_id}?)',
        ) from None


def call_parameter_service(sess: Session, node: str, service: str, srv_type: Any, request: Any,
          timeout: float = CALL_TIMEOUT) -> Any:
    """One service call with a deadline, resent while unanswered.

    Right after discovery a request can be lost: the client sees the server's request
    reader before the server has matched the client's response reader. Parameter
    requests are idempotent, so resending (after 0.5 s, 1 s, 2 s...) is safe.
    """
    client = _client(sess, node, service, srv_type)
    deadline = time.monotonic() + timeout
    if wait_until(lambda: True if client.service_is_ready() else None, timeout) is None:
        raise GraphError(
            f'Wait for service timed out waiting for parameter services for node {node}',
            fix='the node may have died or be busy; check `robot-lab node list`',
        )
    patience = 0.5
    while True:
        future = client.call_async(request)
        answered = threading.Event()
        future.add_done_callback(lambda _f, done=answered: done.set())
        remaining = deadline - time.monotonic()
        if answered.wait(max(0.0, min(patience, remaining))):
            exc = future.exception()
            if exc is not None:
                raise GraphError(f'{node}/{service}: {exc}')
            return future.result()
        client.remove_pending_request(future)
        if time.monotonic() >= deadline:
            raise GraphError(
                f'{node}/{service}: no answer within {timeout:g} s',
                fix='the node may be hung or have died mid-call; check `robot-lab node list`',
            )
        patience *= 2


def param_list(node: str | None = None, prefixes: list[str] | None = None,
               session: Session | None = None, *, include_hidden: bool = False,
               among: list[str] | None = None) -> dict[str, list[str]]:
    """Sorted parameter names per node: of `node`, or of every node in the graph (or of
    the nodes `among`, e.g. a warm daemon's answer, as ros2param asks its daemon).

    Listing many nodes, one without parameter services (a hidden node that never started
    them, a node that died) is left out after the wait, as ros2param goes on past it.
    """
    from rcl_interfaces.srv import ListParameters

    from robot_lab.rclpy_session import is_session_node

    sess = get_session(session)
    if node:
        nodes = [_target(sess, node)]
    elif among is not None:
        nodes = sorted(set(among))
    else:
        nodes = node_list(include_hidden=include_hidden, session=sess)
    result: dict[str, list[str]] = {}
    for full in nodes:
        request = ListParameters.Request(prefixes=list(prefixes or []))
        if not node and is_session_node(full):
            continue  # known to have none: no need to wait for them
        try:
            response = call_parameter_service(sess, full, 'list_parameters', ListParameters,
                                              request)
        except GraphError:
            if node:
                raise
            continue
        result[full] = sorted(response.result.names)
    return result


def _get_values(sess: Session, full: str, names: list[str]) -> list[Any]:
    from rcl_interfaces.srv import GetParameters

    response = call_parameter_service(sess, full, 'get_parameters', GetParameters,
                     GetParameters.Request(names=names))
    return list(response.values)


def _python_value(value: Any) -> Any:
    from rclpy.parameter import parameter_value_to_python

    result = parameter_value_to_python(value)
    return list(result) if isinstance(result, tuple) else result


def param_get(node: str, name: str, session: Session | None = None) -> Any:
    """The parameter's value as Python (int, float, str, bool, list); GraphError if unset."""
    typed = param_get_typed(node, name, session=session)
    return typed[1]


def param_get_typed(node: str, name: str, session: Session | None = None,
                    unset_ok: bool = False) -> tuple[int, Any]:
    """(ParameterType, value): `param get` prints the type's label before the value.

    A parameter the node does not have raises, unless `unset_ok`: then (0, None), the
    PARAMETER_NOT_SET answer `ros2 param get` prints as "Parameter not set.".
    """
    sess = get_session(session)
    full = _target(sess, node)
    values = _get_values(sess, full, [name])
    if unset_ok and values and values[0].type == 0:
        return 0, None
    if not values or values[0].type == 0:
        raise GraphError(
            f"Parameter not set: '{name}' on {full}",
            fix=f'see the parameters it has with `robot-lab param list {full}`',
        )
    return int(values[0].type), _python_value(values[0])


def param_get_text(node: str, name: str,
                   session: Session | None = None) -> tuple[int, str]:
    """(ParameterType, the value as `ros2 param get` prints it); (0, 'None') if unset."""
    ptype, value = param_get_typed(node, name, session=session, unset_ok=True)
    return ptype, str(value)


def type_label(ptype: int) -> str:
    """ros2param's name for a ParameterType value: 'integer', 'double', ..."""
    return _TYPE_STRINGS.get(ptype, f'unknown ({ptype})')


@dataclass
class SetResult:
    """One parameter's outcome, with the node's own reason when it refused."""

    name: str
    successful: bool
    reason: str


def _to_msg(name: str, value: Any) -> Any:
    from rclpy.parameter import Parameter

    from robot_lab.params import parse_value

    if isinstance(value, str):
        value = parse_value(value)  # `ros2 param set`'s typing: 10 int, 0.1 double, abc str
    if isinstance(value, tuple):
        value = list(value)
    try:
        return Parameter(name, value=value).to_parameter_msg()
    except TypeError as exc:
        raise GraphError(f"cannot send {value!r} as parameter '{name}': {exc}") from None


def set_parameters(node: str, values: dict[str, Any],
                   session: Session | None = None) -> list[SetResult]:
    """Set several parameters (each separately, like `param load`); results in order."""
    from rcl_interfaces.srv import SetParameters

    sess = get_session(session)
    full = _target(sess, node)
    request = SetParameters.Request(parameters=[_to_msg(k, v) for k, v in values.items()])
    response = call_parameter_service(sess, full, 'set_parameters', SetParameters, request)
    return [
        SetResult(name, bool(r.successful), str(r.reason))
        for name, r in zip(values, response.results, strict=False)
    ]


def param_set(node: str, name: str, value: Any, session: Session | None = None) -> Any:
    """Set one parameter; a string is typed as `ros2 param set` does ('0.0' -> 0.0).

    Returns the value sent. A refusal raises GraphError carrying the node's own reason
    (wrong type, out of range, read-only...); the node keeps running with the old value.
    """
    (result,) = set_parameters(node, {name: value}, session=session)
    if not result.successful:
        raise GraphError(
            f'Setting parameter failed: {result.reason}',
            fix=f'`robot-lab param describe {absolute_name(node)} {name}` shows its type '
            'and range',
        )
    return _python_value(_to_msg(name, value).value)


def param_delete(node: str, name: str, session: Session | None = None) -> SetResult:
    """Undeclare a parameter, as `ros2 param delete` does: set it to PARAMETER_NOT_SET.

    The node decides: rclpy refuses for a statically typed parameter (the kit's nodes
    declare theirs with a type), and the result carries its reason.
    """
    (result,) = set_parameters(node, {name: None}, session=session)
    return result


@dataclass
class ParamDescription:
    """What `ros2 param describe` shows (ranges as in the node's ParameterDescriptor)."""

    name: str
    type: str
    description: str
    read_only: bool
    min_value: float | int | None
    max_value: float | int | None
    step: float | int | None
    additional_constraints: str


def param_describe(node: str, name: str,
                   session: Session | None = None) -> ParamDescription:
    """Type, description and range of a declared parameter."""
    from rcl_interfaces.srv import DescribeParameters

    sess = get_session(session)
    full = _target(sess, node)
    response = call_parameter_service(sess, full, 'describe_parameters', DescribeParameters,
                     DescribeParameters.Request(names=[name]))
    if not response.descriptors:
        raise GraphError(
            f"Parameter not declared: '{name}' on {full}",
            fix=f'see the parameters it has with `robot-lab param list {full}`',
        )
    d = response.descriptors[0]
    ranges = list(d.floating_point_range) + list(d.integer_range)
    first = ranges[0] if ranges else None
    return ParamDescription(
        name=d.name or name,
        type=type_label(d.type),
        description=d.description,
        read_only=bool(d.read_only),
        min_value=first.from_value if first is not None else None,
        max_value=first.to_value if first is not None else None,
        step=(first.step or None) if first is not None else None,
        additional_constraints=d.additional_constraints,
    )


def param_dump(node: str, as_yaml: bool = False,
               session: Session | None = None) -> dict[str, Any] | str:
    """All of a node's parameters as `{'/node': {'ros__parameters': {...}}}`.

    `as_yaml=True` gives the text `ros2 param dump` prints: a parameter file rcl, `robot-lab
    launch` and `robot-lab param load` accept.
    """
    from robot_lab.params import dump_params

    sess = get_session(session)
    full = _target(sess, node)
    names = param_list(full, session=sess)[full]
    values = _get_values(sess, full, names) if names else []
    flat = {n: _python_value(v) for n, v in zip(names, values, strict=False)}
    if as_yaml:
        return dump_params({full: flat})
    nested: dict[str, Any] = {}
    for dotted, value in flat.items():
        target = nested
        *groups, leaf = dotted.split('.')
        for group in groups:
            target = target.setdefault(group, {})
        target[leaf] = value
    return {full: {'ros__parameters': nested}}


def param_load(node: str, file: str | os.PathLike[str], use_wildcard: bool = True,
               session: Session | None = None) -> list[SetResult]:
    """Set the values a parameter file gives `node` (its `/**` section, then its own).

    The file is checked with rcl's rules first (ParamFileError names the line); results
    come back per parameter, refused ones with the node's reason.
    """
    from robot_lab.params import load_param_file

    return load_sections(node, load_param_file(Path(file)), str(file), use_wildcard,
                         session=session)


def load_sections(node: str, sections: dict[str, dict[str, Any]], file: str,
                  use_wildcard: bool = True, session: Session | None = None) -> list[SetResult]:
    """`param_load` of a file already read (a `param load` the graph daemon answers)."""
    sess = get_session(session)
    full = _target(sess, node)
    values: dict[str, Any] = {}
    for pattern in (('/**',) if use_wildcard else ()) + (full, full.lstrip('/')):
        values.update(sections.get(pattern, {}))
    if not values:
        raise GraphError(
            f'{file}: no parameters for {full}',
            fix=f"put them under '{full}:' or '/**:' then 'ros__parameters:'",
        )
    return set_parameters(full, values, session=sess)



def answer(op: str, request: Mapping[str, Any], session: Session | None = None,
           listed: Callable[[bool], list[str]] | None = None) -> Any:
    """A `param` verb's answer as plain data (the daemon sends it as JSON): the daemon
    answers from its warm session, a command without one from its own, so both print the
    same. `listed(include_hidden)`: the nodes `param list` goes through when given none (the
    daemon's own list; by default the graph's)."""
    sess = get_session(session)
    name = str(request.get('name') or '')
    parameter = str(request.get('parameter', ''))
    if op == 'param_list':
        hidden = bool(request.get('include_hidden'))
        among = None if name else (listed(hidden) if listed is not None
                                   else node_list(include_hidden=hidden, session=sess))
        return {'among': among,
                'by_node': param_list(name or None, list(request.get('prefixes') or []),
                                      sess, among=among)}
    if op == 'param_get':
        return list(param_get_text(name, parameter, session=sess))
    if op == 'param_set':
        return [asdict(r) for r in set_parameters(name, {parameter: str(request['value'])},
                                                  session=sess)]
    if op == 'param_delete':
        return asdict(param_delete(name, parameter, session=sess))
    if op == 'param_describe':
        return asdict(param_describe(name, parameter, session=sess))
    if op == 'param_dump':
        return param_dump(name, as_yaml=True, session=sess)
    if op == 'param_load':
        return [asdict(r) for r in load_sections(
            name, request['sections'], str(request['file']),
            bool(request.get('use_wildcard', True)), session=sess)]
    raise ValueError(f'no param op {op!r}')


PARAM_OPS = ('param_list', 'param_get', 'param_set', 'param_delete', 'param_describe',
             'param_dump', 'param_load')
