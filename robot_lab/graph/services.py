"""Services in the graph: `ros2 service list|type|find|info|call` as data.

`call_service` is the notebook's way to call a service: it waits for the server, sends
the request built from YAML or a dict, and returns the response message (never hangs:
every wait has a timeout that ends in a GraphError saying what to check).
"""

from __future__ import annotations

import threading
import time
import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import (
    LOOKUP_TIMEOUT,
    absolute_name,
    get_session,
    settled,
    wait_until,
)
from robot_lab.graph.nodes import names_and_types
from robot_lab.messages import message_from_yaml

if TYPE_CHECKING:
    from rclpy.client import Client

    from robot_lab.rclpy_session import Session

__all__ = [
    'ServiceInfo',
    'call_service',
    'service_class',
    'service_client',
    'service_find',
    'service_info',
    'service_list',
    'service_list_typed',
    'service_type',
    'wait_for_service',
]


def service_list_typed(include_hidden: bool = False, *, settle: bool = True,
                       session: Session | None = None) -> list[tuple[str, list[str]]]:
    """(name, types) of every service, sorted by name (`ros2 service list -t`).

    With `settle` it first lets discovery finish, like `node_list`.
    """
    sess = get_session(session)
    return names_and_types(sess.node.get_service_names_and_types, include_hidden, settle, sess)


def service_list(types: bool = False, include_hidden: bool = False, *, settle: bool = True,
                 session: Session | None = None) -> list[str] | list[tuple[str, list[str]]]:
    """Service names, sorted; with `types`, (name, types) pairs like `service list -t`."""
    found = service_list_typed(include_hidden, settle=settle, session=session)
    if types:
        return found
    return [name for name, _ in found]


def _types_of(sess: Session, service: str) -> list[str] | None:
    for name, types in sess.node.get_service_names_and_types():
        if name == service:
            return list(types)
    return None


def service_type(name: str, timeout: float = LOOKUP_TIMEOUT,
                 session: Session | None = None) -> list[str]:
    """The service's types (one, unless servers disagree); [] if it is not in the graph
    within `timeout` (`ros2 service type` then prints nothing and exits 1)."""
    sess = get_session(session)
    service = absolute_name(name)
    return wait_until(lambda: _types_of(sess, service), timeout) or []


def service_find(srv_type: str, include_hidden: bool = False, *, settle: bool = True,
                 session: Session | None = None) -> list[str]:
    """Services of exactly type `srv_type` (e.g. `std_srvs/srv/SetBool`), sorted."""
    return [name for name, types in service_list_typed(include_hidden, settle=settle,
                                                       session=session)
            if srv_type in types]


@dataclass
class ServiceInfo:
    """What `ros2 service info` shows: the type(s) and how many clients and servers."""

    name: str
    types: list[str]
    clients: int
    servers: int


def service_info(name: str, timeout: float = LOOKUP_TIMEOUT,
                 session: Session | None = None) -> ServiceInfo:
    """Types and client/server counts of one service; GraphError `Unknown service`."""
    sess = get_session(session)
    service = absolute_name(name)
    if wait_until(lambda: _types_of(sess, service), timeout) is None:
        raise GraphError(
            f"Unknown service '{service}'",
            fix='check the name with `robot-lab service list` (is its server running?)',
        )
    # A fresh session may know the server and not yet every client (or the reverse).
    return settled(sess, lambda: ServiceInfo(
        name=service, types=_types_of(sess, service) or [],
        clients=sess.node.count_clients(service), servers=sess.node.count_services(service),
    ))


def service_class(srv_type: str) -> Any:
    """`std_srvs/srv/SetBool` (or `std_srvs/SetBool`) -> the generated service class."""
    import importlib

    parts = srv_type.strip().split('/')
    if len(parts) == 2:
        parts = [parts[0], 'srv', parts[1]]
    try:
        if len(parts) != 3 or not all(parts):
            raise ValueError(srv_type)
        cls = getattr(importlib.import_module(f'{parts[0]}.{parts[1]}'), parts[2])
    except (AttributeError, ImportError, ValueError):
        raise GraphError(
            f"The passed service type '{srv_type}' is invalid",
            fix='use package/srv/Type, e.g. std_srvs/srv/SetBool '
            '(`robot-lab interface list -s` lists the services this kit has)',
        ) from None
    if not (hasattr(cls, 'Request') and hasattr(cls, 'Response')):
        raise GraphError(f"The passed type '{srv_type}' is not a service",
                         fix='use a .srv type, e.g. std_srvs/srv/Trigger')
    return cls


_CLIENTS: weakref.WeakKeyDictionary[Session, dict[tuple[str, str], Client]] = (
    weakref.WeakKeyDictionary()
)


def service_client(name: str, srv_type: str, session: Session | None = None) -> Client:
    """The session's client for (service, type), made once and kept: repeated calls need
    no new discovery."""
    from rclpy.callback_groups import MutuallyExclusiveCallbackGroup

    sess = get_session(session)
    service = absolute_name(name)
    cls = service_class(srv_type)
    cache = _CLIENTS.setdefault(sess, {})
    key = (service, f'{cls.__module__}.{cls.__name__}')
    if key not in cache:
        cache[key] = sess.node.create_client(
            cls, service, callback_group=MutuallyExclusiveCallbackGroup())
    return cache[key]


def wait_for_service(client: Client, timeout: float | None) -> bool:
    """True once a server of the client's service is available (False after `timeout`)."""
    found = wait_until(lambda: True if client.service_is_ready() else None,
                       1e9 if timeout is None else timeout)
    return found is not None


def call_service(name: str, srv_type: str, values: str | Mapping[str, Any] | Any = None,
                 timeout: float = 10.0, session: Session | None = None) -> Any:
    """Call service `name` once and return its response message.

    `values` is YAML text (`'{data: true}'`, as `ros2 service call` takes), a dict, or a
    Request. Waits up to `timeout` s in all for the server and its answer.

        >>> robot_lab.call_service('/enable', 'std_srvs/srv/SetBool', {'data': True})
        std_srvs.srv.SetBool_Response(success=True, message='enabled')
    """
    sess = get_session(session)
    service = absolute_name(name)
    cls = service_class(srv_type)
    request = values if isinstance(values, cls.Request) else message_from_yaml(
        cls.Request, values)
    client = service_client(service, srv_type, session=sess)
    deadline = time.monotonic() + timeout
    if not wait_for_service(client, timeout):
        raise GraphError(
            f"service '{service}' not available within {timeout:g} s",
            fix='is its server running? `robot-lab service list -t` shows the services',
        )
    return send_request(client, request, max(0.0, deadline - time.monotonic()), service)


def send_request(client: Any, request: Any, timeout: float | None, service: str) -> Any:
    """One request; the response, or GraphError after `timeout` (None: wait for ever)."""
    future = client.call_async(request)
    answered = threading.Event()
    future.add_done_callback(lambda _f: answered.set())
    if not answered.wait(timeout):
        client.remove_pending_request(future)
        raise GraphError(
            f"service '{service}': no response within {timeout:g} s",
            fix='the server may be busy, hung or gone; check `robot-lab service info '
            f'{service}`',
        )
    exc = future.exception()
    if exc is not None:
        raise GraphError(f'Exception while calling service: {exc!r}')
    return future.result()
