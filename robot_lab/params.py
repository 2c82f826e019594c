"""ROS 2 parameter files and values, read with rcl_yaml_param_parser's rules.

One home for parameter YAML: the launcher checks every `--params-file` with
`load_param_file` before it starts anything (rcl would only refuse the file inside the
node, after launch), `parse_value` types a `-p name:=value` string as rcl does, and
`dump_params` / `write_param_file` produce what `ros2 param dump` prints and rcl accepts.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import yaml

from robot_lab.errors import ParamFileError

__all__ = [
    'PARAMS_KEY',
    'dump_params',
    'load_param_file',
    'node_parameters',
    'parse_value',
    'write_param_file',
]

PARAMS_KEY = 'ros__parameters'

_TRUE = {'Y', 'y', 'yes', 'Yes', 'YES', 'true', 'True', 'TRUE', 'on', 'On', 'ON'}
_FALSE = {'N', 'n', 'no', 'No', 'NO', 'false', 'False', 'FALSE', 'off', 'Off', 'OFF'}
# strtoll(value, &end, 0): decimal, 0x hex or 0 octal, the whole string consumed.
_INT = re.compile(r'[+-]?(0[xX][0-9a-fA-F]+|0[0-7]*|[1-9][0-9]*)')
# strtod: decimal floats with optional exponent, or inf/nan words (YAML's .inf spelled too).
_FLOAT = re.compile(r'[+-]?((\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|inf(inity)?|nan)', re.IGNORECASE)
_SPECIAL_FLOATS = {
    '.nan': math.nan, '.NaN': math.nan, '.NAN': math.nan,
    '.inf': math.inf, '.Inf': math.inf, '.INF': math.inf,
    '+.inf': math.inf, '+.Inf': math.inf, '+.INF': math.inf,
    '-.inf': -math.inf, '-.Inf': -math.inf, '-.INF': -math.inf,
}
_TYPE_NAMES = {bool: 'bool', int: 'integer', float: 'double', str: 'string'}
_A_TYPE = {bool: 'a bool', int: 'an integer', float: 'a double', str: 'a string'}


def _scalar(value: str, style: str | None, tag: str | None) -> Any:
    """rcl's get_value(): bool words, then strtoll, then strtod, else string."""
    if tag == 'tag:yaml.org,2002:str' or style in ("'", '"'):
        return value
    if value in _TRUE:
        return True
    if value in _FALSE:
        return False
    if _INT.fullmatch(value):
        return int(value, 0) if not re.fullmatch(r'[+-]?0[0-7]+', value) else int(value, 8)
    if value in _SPECIAL_FLOATS:
        return _SPECIAL_FLOATS[value]
    if _FLOAT.fullmatch(value):
        return float(value)
    return value


def _nested_hint(path: Path) -> str:
    """The seed's flat file rewritten in the nested form rcl wants, on one line."""
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError):
        data = None
    if isinstance(data, dict) and data and PARAMS_KEY not in data:
        flat = {k: v for k, v in data.items() if not isinstance(v, dict)}
        if flat:
            inner = ', '.join(f'{k}: {yaml.safe_dump(v).splitlines()[0]}' for k, v in flat.items())
            return f'nest it under a node name: "/**: {{{PARAMS_KEY}: {{{inner}}}}}"'
    return f'nest the values as "<node name or /**>:\\n  {PARAMS_KEY}:\\n    name: value"'


class _Parser:
    """An event-driven reading of one parameter file, as rcl_yaml_param_parser does it."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.result: dict[str, dict[str, Any]] = {}

    def fail(self, message: str, line: int, fix: str | None = None) -> ParamFileError:
        return ParamFileError(message, file=self.path, line=line, fix=fix)

    def events(self, text: str) -> Iterator[yaml.Event]:
        """PyYAML's events; a syntax error is reported at the last good event's line, as rcl."""
        line = 0
        stream = yaml.parse(text, Loader=getattr(yaml, 'CSafeLoader', yaml.SafeLoader))
        while True:
            try:
                event = next(stream)
            except StopIteration:
                return
            except yaml.MarkedYAMLError as err:
                mark = err.problem_mark or err.context_mark
                problem = err.problem or err.context or 'invalid YAML'
                where = f' ({problem} at line {mark.line + 1})' if mark is not None else ''
                raise ParamFileError(
                    f'Error parsing a event near line {line}{where}', file=self.path,
                    line=mark.line + 1 if mark is not None else line,
                    fix='fix the YAML syntax (indent with spaces, `name: value`, close [ ])',
                ) from None
            if event.start_mark is not None:
                line = event.start_mark.line + 1
            yield event

    def parse(self, text: str) -> dict[str, dict[str, Any]]:
        node_ns: list[str] = []  # keys above ros__parameters
        param_ns: list[str] = []  # nested parameter groups
        level = 'node'
        depth = 0
        node_depths: list[int] = []
        key: str | None = None
        node: str | None = None
        seq: list[Any] | None = None
        seq_line = 0
        for event in self.events(text):
            line = event.start_mark.line + 1 if event.start_mark is not None else 0
            if isinstance(event, yaml.AliasEvent):
                raise self.fail(f'Will not support aliasing at line {line}', line)
            if isinstance(event, yaml.ScalarEvent):
                if seq is not None:
                    value = _scalar(event.value, event.style, event.tag)
                    if seq and type(value) is not type(seq[0]):
                        raise self.fail(
                            'Sequence should be of same type. Value type '
                            f"'{_TYPE_NAMES[type(value)]}' do not belong at line_num {line}",
                            line, fix=f'make every item of the list at line {seq_line} '
                            f'{_A_TYPE[type(seq[0])]} (quote strings, write 1.0 for doubles)',
                        )
                    seq.append(value)
                elif key is None:
                    if not event.value:
                        raise self.fail(f'No key at line {line}', line)
                    key = event.value
                    if level == 'node' and key.startswith(PARAMS_KEY):
                        if not node_ns:
                            raise self.fail(
                                f'There are no node names before {PARAMS_KEY} at line {line}',
                                line, fix=f'put it under a node name: "/**:\\n  {PARAMS_KEY}: ..."'
                                ' (/** matches every node)',
                            )
                        node = '/'.join(node_ns)
                        node = node if node.startswith('/') else '/' + node
                        self.result.setdefault(node, {})
                        level = 'params'
                        key = None
                        param_ns = []
                else:
                    if level != 'params' or node is None:
                        raise self.fail(
                            f'Cannot have a value before {PARAMS_KEY} at line {line}', line,
                            fix=_nested_hint(self.path),
                        )
                    self.result[node]['.'.join([*param_ns, key])] = _scalar(
                        event.value, event.style, event.tag)
                    key = None
            elif isinstance(event, yaml.SequenceStartEvent):
                if key is None:
                    raise self.fail(f'Sequences cannot be key at line {line}', line)
                if level != 'params' or seq is not None:
                    raise self.fail(
                        'Sequences can only be values and not keys in params. '
                        f'Error at line {line}', line, fix=_nested_hint(self.path),
                    )
                seq = []
                seq_line = line
            elif isinstance(event, yaml.SequenceEndEvent):
                assert node is not None and key is not None and seq is not None
                self.result[node]['.'.join([*param_ns, key])] = seq
                seq = None
                key = None
            elif isinstance(event, yaml.MappingStartEvent):
                if seq is not None:
                    raise self.fail(f'Maps cannot be items of a sequence at line {line}', line)
                depth += 1
                if key is not None:
                    if level == 'node':
                        node_ns.append(key)
                        node_depths.append(depth)
                    elif level == 'params':
                        param_ns.append(key)
                    key = None
                elif level == 'params' and depth > len(node_depths) + 2:
                    raise self.fail(f'No key at line {line}', line)
            elif isinstance(event, yaml.MappingEndEvent):
                if level == 'params':
                    if param_ns:
                        param_ns.pop()
                    else:
                        level = 'node'
                        node = None
                elif node_depths and node_depths[-1] == depth:
                    node_depths.pop()
                    node_ns.pop()
                depth -= 1
        return self.result


def load_param_file(path: str | os.PathLike[str]) -> dict[str, dict[str, Any]]:
    """Node name pattern ('/**', '/ns/node') -> flat dotted parameters, or ParamFileError."""
    file = Path(path)
    try:
        text = file.read_text()
    except FileNotFoundError:
        raise ParamFileError(
            'parameter file not found', file=file,
            fix='check the path (in a package, install config/ with data_files and rebuild)',
        ) from None
    except OSError as err:
        raise ParamFileError(f'cannot read parameter file: {err.strerror}', file=file) from None
    return _Parser(file).parse(text)


def parse_value(text: str) -> Any:
    """Type a parameter value string as rcl does for `-p name:=value` and `param set`."""
    try:
        events = list(yaml.parse(text, Loader=getattr(yaml, 'CSafeLoader', yaml.SafeLoader)))
    except yaml.YAMLError:
        return text
    body = [e for e in events if not isinstance(
        e, yaml.StreamStartEvent | yaml.StreamEndEvent | yaml.DocumentStartEvent
        | yaml.DocumentEndEvent)]
    if not body:
        return ''
    first = body[0]
    if isinstance(first, yaml.ScalarEvent) and len(body) == 1:
        return _scalar(first.value, first.style, first.tag)
    if isinstance(first, yaml.SequenceStartEvent) and isinstance(body[-1], yaml.SequenceEndEvent):
        items = body[1:-1]
        if all(isinstance(e, yaml.ScalarEvent) for e in items):
            values = [_scalar(e.value, e.style, e.tag) for e in items]  # type: ignore[attr-defined]
            if values and any(type(v) is not type(values[0]) for v in values):
                raise ParamFileError(
                    f'Sequence should be of same type: {text}',
                    fix='give every item the same type, e.g. [1.0, 2.0] or ["a", "b"]',
                )
            return values
    return text


def _nest(flat: Mapping[str, Any]) -> dict[str, Any]:
    """Dotted names back to nested maps, the way `ros2 param dump` prints them."""
    nested: dict[str, Any] = {}
    for name, value in flat.items():
        target = nested
        *groups, leaf = name.split('.')
        for group in groups:
            target = target.setdefault(group, {})
        target[leaf] = list(value) if isinstance(value, tuple) else value
    return nested


def dump_params(params_by_node: Mapping[str, Mapping[str, Any]]) -> str:
    """YAML as `ros2 param dump` prints it: `node: ros__parameters: {...}`, keys sorted."""
    document = {
        node: {PARAMS_KEY: _nest(params)} for node, params in params_by_node.items()
    }
    text: str = yaml.dump(document, default_flow_style=False)
    return text


def write_param_file(
    params: Mapping[str, Any],
    node: str = '/**',
    directory: str | os.PathLike[str] | None = None,
) -> Path:
    """A temporary `launch_params_*` file as launch_ros writes for name/value params.

    Names stay flat and dotted (`g.x`), exactly as launch_ros dumps them.
    """
    document = {node: {PARAMS_KEY: {
        k: list(v) if isinstance(v, tuple) else v for k, v in params.items()
    }}}
    with tempfile.NamedTemporaryFile(
        'w', prefix='launch_params_', delete=False, dir=directory
    ) as handle:
        yaml.dump(document, handle, default_flow_style=False)
    return Path(handle.name)


def node_parameters(
    files: Iterable[str | os.PathLike[str]], node: str
) -> dict[str, Any]:
    """The values node `node` (fully qualified) gets from `--params-file`s, as rclpy does it.

    rcl merges the files into one list of node sections, ordered by first appearance (a
    later file overrides a value in place). rclpy then walks that list and applies every
    section whose name matches (`/*` one token, `/**` any), later sections winning. So a
    fully qualified section overrides `/**` when it comes after it, as in the usual file
    (`/**` first) and in launch (`from=` files, then the node's own name/value file).
    """
    merged: dict[str, dict[str, Any]] = {}
    for file in files:
        for pattern, values in load_param_file(file).items():
            merged.setdefault(pattern, {}).update(values)
    target = node if node.startswith('/') else '/' + node
    result: dict[str, Any] = {}
    for pattern, values in merged.items():
        regex = re.escape(pattern).replace(re.escape('/*'), r'(/\w+)').replace(r'\*', '*')
        if re.fullmatch(regex, target):
            result.update(values)
    return result
