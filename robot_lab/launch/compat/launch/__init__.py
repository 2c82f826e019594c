"""launch (robot_lab's stand-in): LaunchDescription and the modules launch files import."""

from __future__ import annotations

from collections.abc import Iterable
from typing import NoReturn

from robot_lab.launch.action import LaunchEntity, LaunchStep
from robot_lab.launch.compat_path import unsupported
from robot_lab.launch.conditions import Condition
from robot_lab.launch.context import LaunchContext
from robot_lab.launch.substitutions import SomeSubstitutions, Substitution

from . import (
    actions,
    conditions,
    event_handlers,
    events,
    launch_description_sources,
    substitutions,
)

__all__ = [
    'Action',
    'Condition',
    'LaunchContext',
    'LaunchDescription',
    'LaunchDescriptionEntity',
    'SomeSubstitutionsType',
    'Substitution',
    'actions',
    'conditions',
    'event_handlers',
    'events',
    'launch_description_sources',
    'substitutions',
]

Action = LaunchStep
LaunchDescriptionEntity = LaunchStep
SomeSubstitutionsType = SomeSubstitutions


class LaunchDescription:
    """What generate_launch_description() returns: an ordered list of actions."""

    def __init__(self, initial_entities: Iterable[LaunchEntity] | None = None, *,
                 deprecated_reason: str | None = None) -> None:
        self.entities: list[LaunchEntity] = list(initial_entities or [])
        self.deprecated_reason = deprecated_reason

    def add_action(self, action: LaunchEntity) -> None:
        self.entities.append(action)

    def add_entity(self, entity: LaunchEntity) -> None:
        self.entities.append(entity)

    def describe_sub_entities(self) -> list[LaunchEntity]:
        return list(self.entities)


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch', name, __all__)
