"""launch_ros.events.lifecycle: ChangeState (to emit) and StateTransition (to handle)."""

from __future__ import annotations

from collections.abc import Callable
from typing import NoReturn

from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.events import ChangeState as _ChangeState
from robot_lab.launch.events import StateTransition

__all__ = ['ChangeState', 'StateTransition']


class ChangeState(_ChangeState):
    def __init__(self, *, lifecycle_node_matcher: Callable[[object], bool],
                 transition_id: int) -> None:
        super().__init__(lifecycle_node_matcher, transition_id)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch_ros.events.lifecycle', name, __all__)
