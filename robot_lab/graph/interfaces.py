"""Interface definitions (`ros2 interface show`): the .msg/.srv/.action text the wheels ship.

The message wheels install their definitions under <prefix>/share/<pkg>/msg/; when one is
missing (a package built without them) the text is rebuilt from the generated class.
"""

from __future__ import annotations

import re
from pathlib import Path

from robot_lab.errors import GraphError, PackageNotFoundError
from robot_lab.messages import message_class

__all__ = ['interface_show']

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
