"""The frontend entity model: one tag of an XML or YAML file, as the actions read it.

XML and YAML implement Entity (frontend_xml.py, frontend_yaml.py); an action's `parse`
reads its attributes and sub-entities through it and the helpers below, so actions never
depend on a frontend and frontends never import actions (see registry.py).
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Any

from robot_lab.errors import LaunchError
from robot_lab.launch.substitution_grammar import parse_substitution
from robot_lab.launch.substitutions import Substitution, Text

__all__ = ['Entity', 'env_pairs', 'literal_or_subs', 'required', 'split_cmdline', 'sub_attr']

Subs = list[Substitution]


class Entity:
    """One tag of an XML or YAML launch file: attributes, sub-entities, location.

    XML attributes are strings coerced to the type asked for; YAML values are checked,
    not coerced (as launch_xml and launch_yaml do). Reading marks an attribute used, so
    `assert_parsed` can name the ones nobody read.
    """

    type_name: str
    file: Path
    line: int | None

    def attr(self, name: str, kind: str = 'str', optional: bool = True) -> Any:
        raise NotImplementedError

    def entities(self, name: str) -> list[Entity] | None:
        raise NotImplementedError

    def children(self) -> list[Entity]:
        raise NotImplementedError

    def assert_parsed(self) -> None:
        raise NotImplementedError

    def typed_value(self, value: Any, type_name: str | None) -> Any:
        """A `param` value as this frontend types it (YAML: as written, no coercion)."""
        return value

    def fail(self, message: str, fix: str | None = None) -> LaunchError:
        return LaunchError(message, file=self.file, line=self.line, fix=fix)


def split_cmdline(text: str) -> list[Subs]:
    """launch's ExecuteProcess._parse_cmdline: split on spaces, keeping substitutions whole."""
    result: list[Subs] = []
    arg: Subs = []
    for sub in parse_substitution(text):
        if not isinstance(sub, Text):
            arg.append(sub)
            continue
        tokens = shlex.split(sub.text)
        if not tokens:
            result.append(arg)
            arg = []
            continue
        if sub.text[0].isspace() and arg:
            result.append(arg)
            arg = []
        arg.append(Text(tokens[0]))
        if len(tokens) > 1:
            result.append(arg)
            result.extend([Text(t)] for t in tokens[1:-1])
            arg = [Text(tokens[-1])]
        if sub.text[-1].isspace():
            result.append(arg)
            arg = []
    if arg:
        result.append(arg)
    return [a for a in result if a]


def sub_attr(entity: Entity, name: str, optional: bool = True) -> Subs | None:
    value = entity.attr(name, 'str', optional)
    return None if value is None else parse_substitution(value)


def required(entity: Entity, name: str) -> Subs:
    value = sub_attr(entity, name, optional=False)
    assert value is not None
    return value


def env_pairs(entity: Entity) -> list[tuple[Subs, Subs]] | None:
    items = entity.entities('env')
    if items is None:
        return None
    pairs = [(required(e, 'name'), required(e, 'value')) for e in items]
    for e in items:
        e.assert_parsed()
    return pairs


def literal_or_subs(value: Any) -> Any:
    if not isinstance(value, str):
        return value
    subs = parse_substitution(value)
    if all(isinstance(sub, Text) for sub in subs):
        return ''.join(sub.perform_text() for sub in subs if isinstance(sub, Text))
    return subs
