"""YAML launch files (launch_yaml): `launch:` holding a list of one-key maps.

Built on PyYAML's node graph so every entity keeps its line. Like launch_yaml, values
are type-checked, not coerced: a string attribute must be a YAML string (quote `'true'`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from robot_lab.errors import LaunchError
from robot_lab.launch.action import LaunchDescriptionStep
from robot_lab.launch.entity import Entity
from robot_lab.launch.registry import parse_root

__all__ = ['YamlEntity', 'load_yaml_launch_file']

_PY_TYPES: dict[str, tuple[type, ...]] = {
    'str': (str,), 'bool': (bool,), 'int': (int,), 'float': (float, int),
    'float_or_str': (float, int, str), 'bool_or_str': (bool, str),
}


class YamlEntity(Entity):
    """A YAML map (attributes + `children`) or list (children only)."""

    def __init__(self, node: yaml.Node, type_name: str, file: Path,
                 loader: yaml.SafeLoader, line: int | None = None) -> None:
        self.node, self.type_name, self.file, self.loader = node, type_name, file, loader
        self.line = line if line is not None else node.start_mark.line + 1
        self._read: set[str] = set()
        self._children_read = False

    def _items(self) -> dict[str, yaml.Node]:
        if isinstance(self.node, yaml.MappingNode):
            return {str(k.value): v for k, v in self.node.value}
        return {}

    def _value(self, node: yaml.Node) -> Any:
        return self.loader.construct_object(node, deep=True)

    def attr(self, name: str, kind: str = 'str', optional: bool = True) -> Any:
        items = self._items()
        if name not in items:
            if optional:
                return None
            raise AttributeError(f"Can not find attribute '{name}' in Entity '{self.type_name}'")
        self._read.add(name)
        value = self._value(items[name])
        if kind == 'any':
            if isinstance(value, dict):
                raise TypeError(f"Attribute '{name}' of Entity '{self.type_name}' can not be a map")
            return [str(v) if isinstance(v, str) else v for v in value] \
                if isinstance(value, list) else value
        allowed = _PY_TYPES[kind]
        if not isinstance(value, allowed) or (bool not in allowed and isinstance(value, bool)):
            raise TypeError(
                f"Attribute '{name}' of Entity '{self.type_name}' expected to be of type "
                f"'{kind}', got '{type(value).__name__}'"
                + (" (quote it: launch_yaml does not convert types, e.g. 'true')"
                   if kind == 'str' else ''))
        return value

    def entities(self, name: str) -> list[Entity] | None:
        items = self._items()
        if name not in items:
            return None
        self._read.add(name)
        node = items[name]
        if not isinstance(node, yaml.SequenceNode) or not all(
                isinstance(c, yaml.MappingNode) for c in node.value) or not node.value:
            raise TypeError(f"Attribute '{name}' of Entity '{self.type_name}' expected to be "
                            'a list of dictionaries.')
        return [YamlEntity(c, name, self.file, self.loader) for c in node.value]

    def children(self) -> list[Entity]:
        self._children_read = True
        node = self.node
        if isinstance(node, yaml.MappingNode):
            items = self._items()
            if 'children' not in items:
                raise ValueError(
                    f'Expected entity `{self.type_name}` to have children entities. That can be '
                    'a list of subentities or a dictionary with a `children` list element')
            self._read.add('children')
            node = items['children']
        if not isinstance(node, yaml.SequenceNode):
            raise TypeError(f'Expected a dict or list in `{self.type_name}`')
        result: list[Entity] = []
        for child in node.value:
            if not isinstance(child, yaml.MappingNode) or len(child.value) != 1:
                raise LaunchError('Subentities must be a dictionary with only one key, which '
                                  'is the entity type', file=self.file,
                                  line=child.start_mark.line + 1)
            key, value = child.value[0]
            result.append(YamlEntity(value, str(key.value), self.file, self.loader,
                                     key.start_mark.line + 1))
        return result

    def assert_parsed(self) -> None:
        if isinstance(self.node, yaml.SequenceNode):
            if not self._children_read:
                raise ValueError(f'Unexpected nested entity(ies) found in `{self.type_name}`')
            return
        unread = set(self._items()) - self._read
        if unread:
            raise ValueError(f'Unexpected key(s) found in `{self.type_name}`: {unread}')


def load_yaml_launch_file(path: Path) -> LaunchDescriptionStep:
    """Parse a YAML launch file into actions (nothing is executed yet)."""
    try:
        text = path.read_text()
    except OSError as err:
        raise LaunchError(f'cannot read launch file: {err.strerror}', file=path) from None
    loader = yaml.SafeLoader(text)
    try:
        root = loader.get_single_node()
    except yaml.MarkedYAMLError as err:
        # "while parsing a flow sequence" points at where the construct began: the line to fix
        mark = err.context_mark or err.problem_mark
        detail = '; '.join(str(x) for x in (err.context, err.problem) if x)
        if err.context_mark is not None and err.problem_mark is not None:
            detail += f' (at line {err.problem_mark.line + 1})'
        raise LaunchError(f'malformed YAML: {detail}', file=path,
                          line=mark.line + 1 if mark else None,
                          fix='check the indentation and the `- tag:` list items') from None
    if not isinstance(root, yaml.MappingNode) or len(root.value) != 1:
        raise LaunchError('Expected only one root', file=path,
                          line=root.start_mark.line + 1 if root is not None else None,
                          fix='start the file with `launch:` followed by a list of actions')
    key, value = root.value[0]
    return parse_root(YamlEntity(value, str(key.value), path, loader, key.start_mark.line + 1))
