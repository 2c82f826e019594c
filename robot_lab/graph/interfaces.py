"""Interfaces (`ros2 interface show|list|package|packages|proto`): what the wheels ship.

Which interfaces exist comes from the ament index (`rosidl_interfaces` resources), as
rosidl_runtime_py finds them; definitions are the .msg/.srv/.action text the wheels ship.

The message wheels install their definitions under <prefix>/share/<pkg>/msg/; when one is
missing (a package built without them) the text is rebuilt from the generated class.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Literal

from robot_lab.errors import GraphError, PackageNotFoundError
from robot_lab.messages import message_class

__all__ = [
    'InterfaceKind',
    'interface_list',
    'interface_package',
    'interface_packages',
    'interface_proto',
    'interface_show',
]

InterfaceKind = Literal['msg', 'srv', 'action']
_SUFFIXES: dict[str, tuple[str, ...]] = {
    'msg': ('.idl', '.msg'), 'srv': ('.idl', '.srv'), 'action': ('.idl', '.action'),
}

_PRIMITIVES = {
    'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16',
    'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring',
}
_EXTENSIONS = {'msg': '.msg', 'srv': '.srv', 'action': '.action'}
_FIELD = re.compile(r'^\s*([A-Za-z][\w/]*)(<=\d+)?(\[[^\]]*\])?\s+[A-Za-z]\w*\s*(?:$|#|\s)')


def _split(identifier: str) -> tuple[str, str, str]:
    parts = identifier.strip().split('/')
    if len(parts) == 2:
        parts = [parts[0], 'msg', parts[1]]
    if len(parts) != 3 or parts[1] not in _EXTENSIONS or not all(parts):
        raise GraphError(
            f"Invalid name '{identifier}'. Expected three parts separated by '/'",
            fix='e.g. `robot-lab interface show geometry_msgs/msg/Twist`',
        )
    return parts[0], parts[1], parts[2]


def _definition_lines(identifier: str) -> tuple[str, list[str]]:
    """(package, lines) of an interface's definition file, or rebuilt from its class."""
    from robot_lab.pkg.index import package_share

    package, kind, name = _split(identifier)
    try:
        path = package_share(package) / kind / f'{name}{_EXTENSIONS[kind]}'
    except PackageNotFoundError:
        path = Path('/nonexistent')
    if path.is_file():
        return package, [line.rstrip() for line in path.read_text().splitlines()]
    if kind != 'msg':
        raise GraphError(
            f"Unknown interface '{identifier}'",
            fix=f'is package {package} installed? (`robot-lab interface show` needs its '
            f'share/{package}/{kind}/ files)',
        )
    try:
        cls = message_class(identifier)
    except GraphError:
        raise GraphError(
            f"Could not find the interface '{identifier}'",
            fix=f'check the spelling (package/msg/Type); is package {package} installed?',
        ) from None
    lines = []
    for field, ros_type in cls.get_fields_and_field_types().items():
        lines.append(f'{ros_type} {field}')
    return package, lines


def _nested_type(package: str, line: str) -> str | None:
    """`Vector3  linear` in geometry_msgs -> geometry_msgs/msg/Vector3; None if primitive."""
    code = line.split('#', 1)[0]
    if '=' in code:
        return None  # a constant
    match = _FIELD.match(code)
    if match is None:
        return None
    base = match.group(1)
    if base in _PRIMITIVES:
        return None
    if '/' in base:
        pkg, _, name = base.partition('/')
        return f'{pkg}/msg/{name.split("/")[-1]}'
    return f'{package}/msg/{base}'


def _render(identifier: str, comments: bool, nested_comments: bool, level: int,
            out: list[str]) -> None:
    package, lines = _definition_lines(identifier)
    for raw in lines:
        text = raw
        if not comments:
            stripped = raw.strip()
            if not stripped or stripped.startswith('#'):
                continue
            if '#' in raw and raw.strip() not in ('---',):
                text = raw.split('#', 1)[0].strip()
        out.append(f'{chr(9) * level}{text}' if text else '')
        nested = _nested_type(package, raw) if raw.strip() not in ('---',) else None
        if nested is not None:
            _render(nested, nested_comments, nested_comments, level + 1, out)


def interface_show(type_name: str, comments: bool = True,
                   nested_comments: bool = False) -> str:
    """The definition `ros2 interface show TYPE` prints, nested types expanded with tabs."""
    out: list[str] = []
    _render(type_name, comments, nested_comments, 0, out)
    return '\n'.join(out)



def _index_entries(package: str | None = None) -> dict[str, list[str]]:
    """package -> the lines of its `rosidl_interfaces` resource (`msg/String.idl`, ...).

    With `package`, just that one; PackageNotFoundError if it is not a package at all.
    """
    from robot_lab.pkg.index import ament_prefixes, packages

    known = packages()
    if package is not None and package not in known:
        raise PackageNotFoundError(
            f"Unknown package '{package}'",
            fix='`robot-lab interface packages` lists the packages that have interfaces',
        )
    found: dict[str, list[str]] = {}
    for prefix in ament_prefixes():
        directory = prefix / 'share' / 'ament_index' / 'resource_index' / 'rosidl_interfaces'
        if not directory.is_dir():
            continue
        for marker in sorted(directory.iterdir()):
            if (package is None or marker.name == package) and marker.name not in found:
                found[marker.name] = marker.read_text().splitlines()
    return found


def _names(entries: list[str], kinds: tuple[str, ...]) -> list[str]:
    """`msg/String` style names of the given kinds, sorted (rosidl_runtime_py leaves out
    names with an underscore: the generated `_Goal`, `_Request` parts)."""
    names = set()
    for entry in entries:
        kind, _, rest = entry.partition('/')
        if kind in kinds and '_' not in entry and rest.endswith(_SUFFIXES[kind]):
            names.add(entry.rsplit('.', 1)[0])
    return sorted(names)


def interface_list(kinds: tuple[InterfaceKind, ...] = ('msg', 'srv', 'action'),
                   package: str | None = None) -> dict[str, list[str]]:
    """package -> its interfaces of `kinds` (`msg/String`, ...), packages sorted; a package
    without such interfaces is left out (`ros2 interface list`, `interface package`)."""
    result = {}
    for name, entries in sorted(_index_entries(package).items()):
        names = _names(entries, kinds)
        if names:
            result[name] = names
    return result


def interface_package(package: str,
                      kinds: tuple[InterfaceKind, ...] = ('msg', 'srv', 'action')) -> list[str]:
    """`std_msgs/msg/String`, ... of one package (`ros2 interface package`)."""
    return [f'{package}/{name}' for name in interface_list(kinds, package).get(package, [])]


def interface_packages(kind: InterfaceKind | None = None) -> list[str]:
    """Packages that have interfaces (of `kind`), sorted (`ros2 interface packages`)."""
    if kind is None:
        return sorted(_index_entries())
    return list(interface_list((kind,)))


def _interface_object(identifier: str) -> Any:
    import importlib

    package, kind, name = _split(identifier)
    try:
        return getattr(importlib.import_module(f'{package}.{kind}'), name)
    except (ImportError, AttributeError):
        raise GraphError(
            f"The interface '{identifier}' is invalid",
            fix=f'`robot-lab interface package {package}` lists what {package} has',
        ) from None


def interface_proto(type_name: str) -> str:
    """The YAML of a default message, request or goal (`ros2 interface proto`), the text
    to edit into a `topic pub`, `service call` or `action send_goal` argument."""
    from robot_lab.messages import message_to_yaml

    interface = _interface_object(type_name)
    if hasattr(interface, 'Goal'):
        instance = interface.Goal()
    elif hasattr(interface, 'Request'):
        instance = interface.Request()
    else:
        instance = interface()
    return message_to_yaml(instance)
