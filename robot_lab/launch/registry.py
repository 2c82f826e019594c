"""Launch tags -> actions: each action registers its tag(s) and parses its own entity.

As launch's frontend/expose.py: an action module says `@register('timer')` on its class,
whose `parse(entity)` builds it; a frontend calls `parse_root`/`parse_entity` and never
imports an action. Which action modules exist is the list in actions/__init__.py (a
new tag: one module there, one line in that list).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TypeVar

from robot_lab.errors import LaunchError
from robot_lab.launch.action import LaunchDescriptionStep, LaunchStep
from robot_lab.launch.conditions import Condition
from robot_lab.launch.entity import Entity
from robot_lab.launch.substitution_grammar import parse_substitution
from robot_lab.launch.substitutions import SubstitutionFailure

__all__ = ['TAGS', 'parse_entity', 'parse_root', 'register']

Parser = Callable[[Entity], LaunchStep]
TAGS: dict[str, Parser] = {}
_T = TypeVar('_T', bound=type[LaunchStep])


def register(*tags: str) -> Callable[[_T], _T]:
    """Class decorator: `tags` are parsed by the class's `parse(entity)` classmethod."""

    def decorate(cls: _T) -> _T:
        parse = getattr(cls, 'parse', None)
        if parse is None:
            raise TypeError(f'{cls.__name__} registers {tags} but has no parse(entity)')
        for tag in tags:
            TAGS[tag] = parse
        return cls

    return decorate


def _parser(tag: str) -> Parser | None:
    if not TAGS:  # the actions register themselves when their package is imported
        importlib.import_module('robot_lab.launch.actions')
    return TAGS.get(tag)


def parse_entity(entity: Entity) -> LaunchStep:
    """One tag -> one action, with `if`/`unless` and unused attributes checked."""
    try:
        parser = _parser(entity.type_name)
        if parser is None:
            raise RuntimeError(f'Unrecognized entity of the type: {entity.type_name}')
        when = entity.attr('if')
        unless = entity.attr('unless')
        if when is not None and unless is not None:
            raise RuntimeError("if and unless conditions can't be used simultaneously")
        step = parser(entity)
        entity.assert_parsed()
    except LaunchError:
        raise
    except (ValueError, TypeError, RuntimeError, AttributeError, SubstitutionFailure) as err:
        raise entity.fail(str(err)) from None
    if when is not None:
        step.condition = Condition(parse_substitution(when))
    elif unless is not None:
        step.condition = Condition(parse_substitution(unless), negate=True)
    step.locate(entity.file, entity.line)
    return step


def parse_root(root: Entity) -> LaunchDescriptionStep:
    if root.type_name != 'launch':
        raise root.fail("Expected 'launch' as root tag",
                        fix='wrap the file in <launch> ... </launch> (YAML: launch: [...])')
    root.attr('deprecated')
    # like launch's parse_description, other attributes of the root are ignored
    actions = [parse_entity(child) for child in root.children()]
    description = LaunchDescriptionStep(actions)
    description.locate(root.file, root.line)
    return description
