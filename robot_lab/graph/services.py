"""Services in the graph (`ros2 service list`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot_lab.graph.discovery import get_session
from robot_lab.graph.nodes import names_and_types

if TYPE_CHECKING:
    from robot_lab.context import Session

__all__ = ['service_list', 'service_list_typed']


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
