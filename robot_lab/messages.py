"""ROS messages as data: type names ↔ classes, message ↔ dict/YAML, field paths.

rosidl_runtime_py (what ros2cli uses for this) is not among the PyPI wheels, so this is
robot_lab's small equivalent, built on the generated classes' own introspection
(`get_fields_and_field_types()`). One home for it: `topic echo/pub`, plots and bags use it.
"""

from __future__ import annotations

import functools
import importlib
import math
import sys
from collections.abc import Callable, Mapping
from typing import Any

import yaml

from robot_lab.errors import GraphError

__all__ = [
    'field_value',
    'message_class',
    'message_from_yaml',
    'message_to_dict',
    'message_to_yaml',
    'stamped_message_from_yaml',
    'type_name',
]


def message_class(type_name: str) -> Any:
    """`std_msgs/msg/Float32` (or `std_msgs/Float32`) -> the generated class."""
    parts = type_name.strip().split('/')
    if len(parts) == 2:
        parts = [parts[0], 'msg', parts[1]]
    if len(parts) != 3 or not all(parts):
        raise GraphError(
            f"The passed message type '{type_name}' is invalid",
            fix='use the form package/msg/Type, e.g. std_msgs/msg/String',
        )
    package, kind, name = parts
    try:
        module = importlib.import_module(f'{package}.{kind}')
        return getattr(module, name)
    except (ImportError, AttributeError):
        raise GraphError(
            f"The message type '{type_name}' is invalid",
            fix=f"no interface '{name}' in package '{package}' "
            '(see `robot-lab interface show` for the types this kit has)',
        ) from None


def type_name(msg_or_class: Any) -> str:
    """The ROS name of a message instance or class: `geometry_msgs/msg/Twist`."""
    cls = msg_or_class if isinstance(msg_or_class, type) else type(msg_or_class)
    package = cls.__module__.split('.')[0]
    kind = cls.__module__.split('.')[1] if '.' in cls.__module__ else 'msg'
    return f'{package}/{kind}/{cls.__name__}'


def _is_message(value: Any) -> bool:
    return hasattr(value, 'get_fields_and_field_types')


def _plain(value: Any) -> Any:
    if _is_message(value):
        return message_to_dict(value)
    if isinstance(value, bytes):
        return list(value)
    if isinstance(value, list | tuple) or type(value).__name__ in ('array', 'ndarray'):
        return [_plain(v) for v in value]
    if type(value).__module__ == 'numpy' and hasattr(value, 'item'):
        return value.item()  # a fixed-size array's element (uint8[16] of a GID): plain int
    return value


def message_to_dict(msg: Any, *, no_arr: bool = False, no_str: bool = False,
                    truncate_length: int | None = None) -> dict[str, Any]:
    """Field name -> plain Python value, nested messages as dicts (ordered as declared).

    `no_arr`, `no_str` and `truncate_length` abridge as `ros2 topic echo` does
    (`<sequence type: float64, length: 9>`, `<string length: <5>>`, `...`).
    """
    if not (no_arr or no_str or truncate_length is not None):
        return {name: _plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    return {
        name: _abridged(getattr(msg, name), slot, no_arr, no_str, truncate_length)
        for name, slot in zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES, strict=False)
    }


def _slot_type_name(slot: Any) -> str:
    kind = type(slot).__name__
    if kind == 'BasicType':
        return str(slot.typename)
    if kind in ('UnboundedString', 'BoundedString'):
        return 'string'
    if kind in ('UnboundedWString', 'BoundedWString'):
        return 'wstring'
    if kind == 'NamespacedType':
        return '/'.join(slot.namespaced_name())
    return str(getattr(slot, 'name', 'unknown'))


def _array_info(value: Any, slot: Any) -> str:
    item = _slot_type_name(slot.value_type)
    kind = type(slot).__name__
    if kind == 'Array':
        return f'<array type: {item}[{slot.size}]>'
    if kind == 'BoundedSequence':
        return f'<sequence type: {item}[{slot.maximum_size}], length: {len(value)}>'
    return f'<sequence type: {item}, length: {len(value)}>'


def _abridged(value: Any, slot: Any, no_arr: bool, no_str: bool, limit: int | None) -> Any:
    if _is_message(value):
        return message_to_dict(value, no_arr=no_arr, no_str=no_str, truncate_length=limit)
    if isinstance(value, str):
        if no_str:
            return f'<string length: <{len(value)}>>'
        return value[:limit] + '...' if limit is not None and len(value) > limit else value
    if isinstance(value, list | tuple | bytes) or type(value).__name__ in ('array', 'ndarray'):
        if no_arr and slot is not None and hasattr(slot, 'value_type'):
            return _array_info(value, slot)
        items = [_abridged(v, None, no_arr, no_str, limit) for v in value]
        if limit is not None and len(items) > limit:
            return [*items[:limit], '...']
        return items
    return _plain(value)


class _EchoDumper(yaml.SafeDumper):
    """Dumps floats the way ros2 topic echo does (22.5, not 22.500000001 from float32)."""


def _float_repr(dumper: yaml.SafeDumper, value: float) -> yaml.Node:
    if math.isnan(value):
        text = '.nan'
    elif math.isinf(value):
        text = '.inf' if value > 0 else '-.inf'
    else:
        text = repr(value)
    return dumper.represent_scalar('tag:yaml.org,2002:float', text)


_EchoDumper.add_representer(float, _float_repr)


def message_to_yaml(msg: Any, *, no_arr: bool = False, no_str: bool = False,
                    truncate_length: int | None = None, flow_style: bool = False) -> str:
    """The YAML `ros2 topic echo` prints for one message (without the `---`);
    `flow_style` is `echo --flow-style`'s one-line `{a: 1, b: {c: 2}}`."""
    data = message_to_dict(msg, no_arr=no_arr, no_str=no_str, truncate_length=truncate_length)
    return dict_to_yaml(data, flow_style=flow_style)


def dict_to_yaml(data: Mapping[str, Any], *, flow_style: bool = False) -> str:
    """A message_to_dict() result (perhaps edited) as `ros2 … echo` prints it."""
    return yaml.dump(data, Dumper=_EchoDumper, default_flow_style=flow_style, sort_keys=False,
                     allow_unicode=True, width=sys.maxsize)


def message_to_csv(msg: Any, *, no_arr: bool = False, no_str: bool = False,
                   truncate_length: int | None = None) -> str:
    """`ros2 topic echo --csv`: every leaf field in order, joined by commas
    (rosidl_runtime_py's message_to_csv rules: '...' past the cut, values as str())."""

    def text(value: Any, slot: Any) -> str:
        if _is_message(value):
            return message_to_csv(value, no_arr=no_arr, no_str=no_str,
                                  truncate_length=truncate_length)
        if isinstance(value, str):
            if no_str:
                return f'<string length: <{len(value)}>>'
            cut = truncate_length is not None and len(value) > truncate_length
            return value[:truncate_length] + '...' if cut else value
        if isinstance(value, list | tuple) or type(value).__name__ in ('array', 'ndarray'):
            if no_arr and slot is not None and hasattr(slot, 'value_type'):
                return str(_array_info(value, slot))
            items = list(value)
            cut = truncate_length is not None and len(items) > truncate_length
            shown = [text(v, None) for v in (items[:truncate_length] if cut else items)]
            return ','.join([*shown, '...'] if cut else shown)
        return str(value.item() if hasattr(value, 'item') else value)

    return ','.join(text(getattr(msg, name), slot)
                    for name, slot in zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES,
                                              strict=True))


Stamper = Callable[[Any], None]


def _qualified(value: Any) -> str:
    cls = type(value)
    return f'{cls.__module__.split(".")[0]}/{cls.__name__}'


def _fill(msg: Any, values: Mapping[str, Any], path: str, stamps: list[Stamper] | None) -> None:
    """Set `values` into `msg` (rosidl_runtime_py's set_message_fields rules).

    With `stamps` (a list), ros2cli's expansions apply: a `std_msgs/Header` given as
    `auto` stays empty (frame_id '') and its stamp is registered in `stamps`; a
    `builtin_interfaces/Time` given as `now` is registered too. The caller sets them to the
    current time at each publish.
    """
    fields = msg.get_fields_and_field_types()
    if hasattr(msg, '_check_fields'):
        # Jazzy's classes check a value's type only with ROS_PYTHON_CHECK_FIELDS=1; without
        # it `stamp: yesterday` would be accepted here and fail later, inside publish().
        msg._check_fields = True
    for key, value in values.items():
        if key not in fields:
            raise GraphError(
                f"Failed to populate field: '{path}{key}' is not a field of {type_name(msg)}",
                fix=f'fields are: {", ".join(fields)}',
            )
        current = getattr(msg, key)
        if stamps is not None and _is_message(current) and isinstance(value, str):
            if _qualified(current) == 'std_msgs/Header' and value == 'auto':
                stamps.append(functools.partial(setattr, current, 'stamp'))
                continue
            if _qualified(current) == 'builtin_interfaces/Time' and value == 'now':
                stamps.append(functools.partial(setattr, msg, key))
                continue
        if _is_message(current) and isinstance(value, Mapping):
            _fill(current, value, f'{path}{key}.', stamps)
            continue
        try:
            value = _coerce(msg, key, current, value, f'{path}{key}', stamps)
            setattr(msg, key, value)
        except (AssertionError, TypeError, ValueError) as exc:
            raise GraphError(
                f"Failed to populate field '{path}{key}' ({fields[key]}): {exc}"
            ) from None


def _coerce(msg: Any, key: str, current: Any, value: Any, path: str,
            stamps: list[Stamper] | None) -> Any:
    """A YAML value in the field's Python type: ints for floats, dicts for messages in
    sequences (`points: [{x: 1.0}]`), as ros2 topic pub accepts them."""
    if isinstance(current, float) and type(value) is int:
        return float(value)  # YAML `1` for a float field
    if isinstance(value, list | tuple) and any(isinstance(v, Mapping) for v in value):
        slot = dict(zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES, strict=False))[key]
        item_type: Any = getattr(slot, 'value_type', None)
        if type(item_type).__name__ == 'NamespacedType':
            cls = message_class('/'.join(item_type.namespaced_name()))
            items = []
            for i, item in enumerate(value):
                sub = cls()
                if not isinstance(item, Mapping):
                    raise TypeError(f'item {i} must be a dictionary, not {item!r}')
                _fill(sub, item, f'{path}[{i}].', stamps)
                items.append(sub)
            return items
    return value


def message_from_yaml(type_or_class: str | Any, text: str | Mapping[str, Any] | None) -> Any:
    """Build a message from YAML text (`topic pub`'s argument) or a mapping.

    `header: auto` and Time fields given as `now` get the current time (once); see
    `stamped_message_from_yaml` to restamp at each publish as `ros2 topic pub` does.
    """
    msg, restamp = stamped_message_from_yaml(type_or_class, text)
    restamp()
    return msg


def stamped_message_from_yaml(type_or_class: str | Any, text: str | Mapping[str, Any] | None,
                              ) -> tuple[Any, Callable[[], bool]]:
    """(message, restamp): `restamp()` sets every `header: auto` stamp and every Time
    given as `now` to the current ROS time (rclpy's system clock) and says whether there
    were any. ros2 topic pub calls it before each publish."""
    cls = message_class(type_or_class) if isinstance(type_or_class, str) else type_or_class
    values = _yaml_values(text)
    msg = cls()
    stamps: list[Stamper] = []
    _fill(msg, values, '', stamps)

    def restamp() -> bool:
        if not stamps:
            return False
        from rclpy.clock import Clock
        from rclpy.clock_type import ClockType

        now = Clock(clock_type=ClockType.SYSTEM_TIME).now().to_msg()
        for stamp in stamps:
            stamp(now)
        return True

    return msg, restamp


def _yaml_values(text: str | Mapping[str, Any] | None) -> Mapping[str, Any]:
    if isinstance(text, str):
        try:
            values = yaml.safe_load(text) if text.strip() else {}
        except yaml.YAMLError as exc:
            mark = getattr(exc, 'problem_mark', None)
            where = f' at column {mark.column + 1}' if mark is not None else ''
            raise GraphError(
                f'the passed value needs to be a dictionary in YAML format{where}: {text!r}',
                fix="quote it and use YAML, e.g. '{data: 22.5}' or \"{linear: {x: 0.5}}\"",
            ) from None
    else:
        values = text or {}
    if values is None:
        values = {}
    if not isinstance(values, Mapping):
        raise GraphError(
            f'the passed value needs to be a dictionary in YAML format: {text!r}',
            fix="e.g. '{data: 22.5}'",
        )
    return values


def field_value(msg: Any, path: str) -> Any:
    """Follow a field path like `linear.x`, `linear/x` or `data` into a message."""
    value = msg
    for part in path.replace('/', '.').split('.'):
        if not part:
            continue
        if isinstance(value, list | tuple) or type(value).__name__ == 'array':
            try:
                value = value[int(part)]
                continue
            except (ValueError, IndexError):
                raise GraphError(f"invalid index '{part}' in field path '{path}'") from None
        if not hasattr(value, part) or not _is_message(value):
            have = ', '.join(value.get_fields_and_field_types()) if _is_message(value) else 'none'
            raise GraphError(
                f"'{part}' in field path '{path}' is not a field of "
                f'{type_name(value) if _is_message(value) else type(value).__name__}',
                fix=f'fields are: {have}',
            )
        value = getattr(value, part)
    return value
