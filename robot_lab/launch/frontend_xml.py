"""XML launch files (launch_xml): elements with source lines -> the shared tag parsers.

`xml_lines` keeps each element's line, so every error can say `robot.launch.xml:12`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from robot_lab.errors import LaunchError
from robot_lab.launch.action import LaunchDescriptionStep
from robot_lab.launch.entity import Entity
from robot_lab.launch.registry import parse_root
from robot_lab.launch.substitutions import coerce
from robot_lab.xml_lines import XmlElement, parse_xml_lines

__all__ = ['XmlEntity', 'load_xml_launch_file', 'parse_xml']


def parse_xml(path: Path) -> XmlElement:
    """The element tree of `path`, each element with its line; LaunchError if malformed."""
    try:
        text = path.read_bytes()
    except OSError as err:
        raise LaunchError(f'cannot read launch file: {err.strerror}', file=path) from None
    return parse_xml_lines(text, str(path), XmlElement, LaunchError, what='malformed XML',
                           fix='check the tags are closed and attributes quoted')


_KINDS = {'bool': 'bool', 'int': 'int', 'float': 'float'}


class XmlEntity(Entity):
    """An XML element: attributes are strings, coerced when a type is asked for."""

    def __init__(self, element: XmlElement, file: Path) -> None:
        self.element, self.file = element, file
        self.type_name, self.line = element.tag, element.line
        self._read_attrs: set[str] = set()
        self._read_tags: set[str] = set()

    def attr(self, name: str, kind: str = 'str', optional: bool = True) -> Any:
        attrib = self.element.attrib
        if name not in attrib:
            if optional:
                return None
            raise AttributeError(
                f"Attribute '{name}' of type '{_type_label(kind)}' not found in Entity "
                f"'{self.type_name}'")
        self._read_attrs.add(name)
        value: Any = attrib[name]
        if f'{name}-sep' in attrib:
            self._read_attrs.add(f'{name}-sep')
            value = value.split(attrib[f'{name}-sep'])
        if kind in ('str', 'any'):
            return value
        base = kind.split('_or_')[0]
        try:
            return coerce(value, _KINDS[base])
        except ValueError:
            if kind.endswith('_or_str'):
                return value
            raise TypeError(
                f"Attribute '{name}' of Entity '{self.type_name}' expected to be of type "
                f"'{_type_label(kind)}'.'{value}' can not be converted to one of those types"
            ) from None

    def typed_value(self, value: Any, type_name: str | None) -> Any:
        """launch_xml coerces as it reads (YAML rules untyped); text it cannot coerce stays
        text, so `$(var n)` can be evaluated and typed at launch."""
        if isinstance(value, list):
            item = type_name[len('list_of_'):] if type_name and type_name.startswith(
                'list_of_') else None
            return [self.typed_value(v, item) for v in value]
        try:
            return coerce(value, type_name)
        except ValueError:
            return value

    def entities(self, name: str) -> list[Entity] | None:
        found = [XmlEntity(c, self.file) for c in self.element.children if c.tag == name]
        if not found:
            return None
        self._read_tags.add(name)
        return list(found)

    def children(self) -> list[Entity]:
        self._read_tags.update(c.tag for c in self.element.children)
        return [XmlEntity(c, self.file) for c in self.element.children]

    def assert_parsed(self) -> None:
        tags = {c.tag for c in self.element.children} - self._read_tags
        if tags:
            raise ValueError(f'Unexpected nested tag(s) found in `{self.type_name}`: {tags}')
        attrs = set(self.element.attrib) - self._read_attrs
        if attrs:
            raise ValueError(f'Unexpected attribute(s) found in `{self.type_name}`: {attrs}')


def _type_label(kind: str) -> str:
    return {'str': "<class 'str'>", 'bool': "<class 'bool'>", 'int': "<class 'int'>",
            'float': "<class 'float'>"}.get(kind.split('_or_')[0], kind)


def load_xml_launch_file(path: Path) -> LaunchDescriptionStep:
    """Parse an XML launch file into actions (nothing is executed yet)."""
    return parse_root(XmlEntity(parse_xml(path), path))
