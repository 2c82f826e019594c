"""Node parameters in launch: values typed as launch_ros types them, files checked.

A `<param>` (or `parameters=[...]`) becomes ParamValue / ParamFileRef when parsed and a
typed value or a checked `--params-file` when the node is executed.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias, TypeGuard

import yaml

from robot_lab.errors import LaunchError, ParamFileError
from robot_lab.launch.action import Subs, subs
from robot_lab.launch.entity import Entity, literal_or_subs
from robot_lab.launch.plan import LaunchPlan
from robot_lab.launch.substitution_grammar import parse_substitution
from robot_lab.launch.substitutions import (
    SomeSubstitutions,
    Substitution,
    SubstitutionFailure,
    coerce,
    perform,
)
from robot_lab.params import load_param_file

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['NodeParameters', 'ParamFileRef', 'ParamValue', 'check_param_file', 'check_param_files',
           'flatten_params', 'is_subs', 'param_value', 'parse_param_entities',
           'substituted_param_file']

@dataclass
class ParamValue:
    """A parameter value: a Python value, or substitutions typed by `value_type` (None=YAML)."""

    value: object
    value_type: str | None = None
    where: tuple[Path, int | None] | None = None  # the `<param>` it came from


@dataclass
class ParamFileRef:
    """A `from=` / ParameterFile parameter file."""

    path: Subs
    allow_substs: bool = False
    where: tuple[Path, int | None] | None = None


# One entry of a Node's `parameters`: names (nested dicts allowed) -> values, or a file.
NodeParameters: TypeAlias = Mapping[SomeSubstitutions, object] | ParamFileRef


def substituted_param_file(path: str, context: LaunchContext) -> str:
    """`allow_substs`: the file with its `$(...)` performed, in a launch_params_ file."""
    try:
        text = perform(parse_substitution(Path(path).read_text()), context)
    except FileNotFoundError:
        raise context.error(f'parameter file not found: {path}') from None
    try:
        yaml.safe_load(text)
    except yaml.YAMLError:
        raise context.error('The substituted parameter file is not a valid yaml file') from None
    with tempfile.NamedTemporaryFile('w', prefix='launch_params_', delete=False) as handle:
        handle.write(text)
    return handle.name


def check_param_file(path: str, context: LaunchContext) -> None:
    """rcl would refuse the file inside the node, after start; refuse it now, located."""
    try:
        load_param_file(path)
    except ParamFileError as err:
        used = context.where()
        where = f' (used at {used})' if used else ''
        raise ParamFileError(err.message + where, file=err.file, line=err.line,
                             fix=err.fix) from None


def is_subs(value: object) -> TypeGuard[list[Substitution]]:
    return isinstance(value, list) and bool(value) and \
        all(isinstance(x, Substitution) for x in value)


def param_value(value: object, context: LaunchContext, name: str) -> Any:
    """launch_ros's evaluation of one parameter value.

    Substitutions are performed, then typed by `value_type` (None: YAML rules); literal
    values are already typed (the XML frontend coerced them, YAML and Python give them).
    """
    if isinstance(value, ParamValue):
        raw, value_type = value.value, value.value_type
    else:
        raw, value_type = value, None
    item_type = value_type[len('list_of_'):] if value_type and value_type.startswith(
        'list_of_') else None
    if isinstance(raw, Substitution):
        raw = [raw]
    try:
        if is_subs(raw):
            text = perform(raw, context)
            if value_type is None and not text:
                return ''
            result = coerce(text, value_type)
            return _uniform(result, name) if isinstance(result, list) else result
        if isinstance(raw, list | tuple):
            items = []
            for item in raw:
                if isinstance(item, Substitution) or is_subs(item):
                    item = coerce(perform(subs(item), context), item_type)
                elif isinstance(item, str) and item_type is not None:
                    item = coerce(item, item_type)
                items.append(item)
            if all(isinstance(x, int | float) and not isinstance(x, bool) for x in items) and \
                    (item_type == 'float' or any(isinstance(x, float) for x in items)):
                items = [float(x) for x in items]
            return _uniform(items, name)
        if isinstance(raw, str) and value_type not in (None, 'str', 'yaml'):
            return coerce(raw, value_type)
    except ValueError as err:
        raise ValueError(f'parameter {name}: {err}') from None
    if isinstance(raw, bool | int | float | str | bytes):
        return raw
    raise TypeError(f'Unexpected type for parameter value {raw!r}')


def _uniform(items: list[Any], name: str) -> list[Any]:
    if not items or any(type(x) is not type(items[0]) for x in items) or \
            type(items[0]) not in (bool, int, float, str):
        raise TypeError(
            'Expected a non-empty sequence, with items of uniform type. Allowed sequence item '
            f'types are bool, int, float, str. Got inconsistent input for "{name}"')
    return items


def flatten_params(params: Mapping[SomeSubstitutions, object], context: LaunchContext,
             prefix: str = '') -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = perform(subs(key), context)
        full = f'{prefix}.{name}' if prefix else name
        if isinstance(value, Mapping):
            out.update(flatten_params(value, context, full))
            continue
        try:
            out[full] = param_value(value, context, full)
        except (SubstitutionFailure, ValueError, TypeError) as err:
            where = getattr(value, 'where', None)
            if where is None:
                raise
            message = str(err) if str(err).startswith('parameter ') else \
                f'parameter {full}: {err}'
            raise LaunchError(message, file=where[0], line=where[1]) from None
    return out


def parse_param_entities(items: list[Entity]) -> list[NodeParameters]:
    """launch_ros's Node.parse_nested_parameters: one entry per top-level `param`."""

    def nested(entries: list[Entity]) -> dict[SomeSubstitutions, object]:
        out: dict[SomeSubstitutions, object] = {}
        for param in entries:
            try:
                one(param, out)
            except LaunchError:
                raise
            except (ValueError, TypeError, RuntimeError, AttributeError,
                    SubstitutionFailure) as err:  # located at the <param>, not its <node>
                raise param.fail(str(err)) from None
        return out

    def one(param: Entity, out: dict[SomeSubstitutions, object]) -> None:
        name = param.attr('name', optional=False)
        type_name = param.attr('type')
        if type_name is not None and type_name not in (
                'str', 'bool', 'float', 'int', 'yaml', 'list_of_str', 'list_of_bool',
                'list_of_float', 'list_of_int'):
            raise ValueError(f"Got invalid type identifier '{type_name}'")
        value = param.attr('value', 'any')
        if value is not None:
            value = param.typed_value(value, type_name)
        children = param.entities('param')
        param.assert_parsed()
        if value is not None and children:
            raise RuntimeError('nested parameters and value attributes are mutually exclusive')
        if type_name is not None and children:
            raise RuntimeError('nested parameters and type attributes are mutually exclusive')
        if value is not None:
            # parse_if_substitutions: text with substitutions is evaluated at launch
            if isinstance(value, list):
                value = [literal_or_subs(v) for v in value]
            else:
                value = literal_or_subs(value)
            out[name] = ParamValue(value, type_name, (param.file, param.line))
        elif children:
            out[name] = nested(children)
        else:
            raise RuntimeError('either a value attribute or nested params are needed')

    result: list[NodeParameters] = []
    for param in items:
        source = param.attr('from')
        allow = param.attr('allow_substs', 'bool')
        name = param.attr('name', 'str', optional=True) if source is not None else None
        if source is not None and name is not None:
            raise RuntimeError('name and from attributes are mutually exclusive')
        if source is not None:
            param.assert_parsed()
            result.append(ParamFileRef(parse_substitution(source), bool(allow),
                                       (param.file, param.line)))
        else:
            if allow is not None:
                raise RuntimeError("'allow_substs' can only be used together with 'from' attribute")
            result.append(nested([param]))
    return result


def check_param_files(plan: LaunchPlan) -> None:
    """Refuse the plan if any process would get a parameter file rcl cannot parse.

    rcl only finds out in the child, after the launch has started its siblings; checking
    first means a bad file stops everything with one clear line and nothing running.
    """
    seen: set[str] = set()
    for spec in plan.processes():
        for path in spec.param_files:
            if path in seen:
                continue
            seen.add(path)
            try:
                load_param_file(path)
            except ParamFileError:
                raise
            except OSError as exc:
                raise ParamFileError(
                    f'cannot read parameter file: {exc.strerror or exc}', file=path,
                    fix=f'check the path given to {spec.label}',
                ) from None
