"""launch_ros.event_handlers: OnStateTransition (a lifecycle node changed state)."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.actions.event_handlers import EventHandler, Response
from robot_lab.launch.compat_path import unsupported

__all__ = ['OnStateTransition']


class OnStateTransition(EventHandler):
    launch_name = 'OnStateTransition'

    def __init__(self, *, entities: Response, target_lifecycle_node: object = None,
                 transition: str | None = None, start_state: str | None = None,
                 goal_state: str | None = None, **_: object) -> None:
        wanted = {'transition': transition, 'start_state': start_state,
                  'goal_state': goal_state}

        def accepts(event: object) -> bool:
            return all(value is None or getattr(event, key) == value
                       for key, value in wanted.items())

        super().__init__('state_transition', target_lifecycle_node, {'entities': entities},
                         accepts=accepts)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.event_handlers', name, __all__)
