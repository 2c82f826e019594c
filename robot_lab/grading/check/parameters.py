"""Checks of parameters: a node's values, descriptors and on-set callbacks; parameter files."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.check.base import CheckError, judged, passed, same_value, wait_until
from robot_lab.grading.check.graph import topic_publishes

__all__ = [
    'param_applied',
    'param_count',
    'param_described',
    'param_equals',
    'param_file_accepted',
    'param_refused',
]


@judged
def param_equals(node: str, name: str, value: Any, timeout: float = 5.0) -> None:
    """`ros2 param get <node> <name>` gives `value` (floats compared with tolerance)."""
    from robot_lab.graph.api import param_get

    full = '/' + node.lstrip('/')
    got: list[Any] = []

    def _probe() -> bool:
        try:
            got.append(param_get(full, name))
        except RobotLabError as err:
            got.append(err)
            return False
        return same_value(got[-1], value)

    if not wait_until(_probe, timeout, interval=0.2):
        from robot_lab.graph.api import node_list

        last = got[-1] if got else None
        if isinstance(last, RobotLabError) and full not in node_list(settle=False):
            raise CheckError(f'{full} {name} = {value!r}', f'{full} is not running',
                             'start it, and read its output: a node that refuses a value '
                             'from the parameter file stops at start and says why')
        seen = last.message if isinstance(last, RobotLabError) else f'it is {last!r}'
        hint = 'set it (param set, a slider, or the parameter file) and check the node ' \
            'accepted it'
        if isinstance(last, int | float) and not isinstance(last, bool) and \
                isinstance(value, float) != isinstance(last, float):
            hint = (f'the node holds {type(last).__name__} {last!r}, the check expects '
                    f'{type(value).__name__} {value!r}: in YAML `22` is an integer and '
                    '`22.0` a double')
        raise CheckError(f'{full} {name} = {value!r}', seen, hint)
    passed(f'{full} {name} = {value!r}')


@judged
def param_file_accepted(path: str | Path) -> None:
    """rcl's rules accept the parameter file (what a node given `--params-file` reads)."""
    from robot_lab.params import load_param_file

    try:
        sections = load_param_file(path)
    except RobotLabError as err:
        raise CheckError(f'{Path(path).name} accepted by rcl', f'it is refused: {err.message}',
                         err.fix or 'nest the values under `<node name>: ros__parameters:`') \
            from None
    if not sections:
        raise CheckError(f'{Path(path).name} to set parameters', 'it has no node section',
                         'add `/**:` (or a node name) with `ros__parameters:` under it')
    summary = '; '.join(f'{node} sets {", ".join(sorted(values))}'
                        for node, values in sections.items())
    passed(f'rcl accepts {Path(path).name}: {summary}')


@judged
def param_count(path: str | Path, at_least: int) -> None:
    """The parameter file sets at least `at_least` parameters (all node sections together)."""
    from robot_lab.params import load_param_file

    sections = load_param_file(path)
    names = sorted({f'{node}/{name}' for node, values in sections.items() for name in values})
    if len(names) < at_least:
        raise CheckError(f'at least {at_least} parameters in {Path(path).name}',
                         f'it sets {len(names)}: {", ".join(names) or "none"}',
                         'add the parameters your nodes declare, under their node sections')
    passed(f'{Path(path).name} sets {len(names)} parameters')


@judged
def param_described(node: str, name: str, low: float | None = None,
                    high: float | None = None) -> None:
    """`ros2 param describe` shows a description and, given `low`/`high`, that range."""
    from robot_lab.graph.api import param_describe

    full = '/' + node.lstrip('/')
    want = f'{full} {name} described' + (f' with the range {low:g} … {high:g}'
                                          if low is not None and high is not None else '')
    try:
        d = param_describe(full, name)
    except RobotLabError as err:
        raise CheckError(want, err.message, 'declare it with declare_parameter(name, default, '
                                            'ParameterDescriptor(...))') from None
    rng = 'no range' if d.min_value is None else f'the range {d.min_value:g} … {d.max_value:g}'
    if d.min_value is not None:
        as_int = isinstance(d.min_value, int)
        if (d.type == 'double' and as_int) or (d.type == 'integer' and not as_int):
            given, needed = (('integer_range', 'floating_point_range=[FloatingPointRange(…)]')
                             if as_int else
                             ('floating_point_range', 'integer_range=[IntegerRange(…, step=1)]'))
            raise CheckError(want, f'{name} is of type {d.type}, but its range is given as '
                             f'{given}', f'a {d.type} takes {needed}: rclpy checks a range '
                             'only against a value of its own type')
    if not d.description or (low is not None and (d.min_value, d.max_value) != (low, high)):
        raise CheckError(want, f'its description is {d.description!r} with {rng}',
                         'pass ParameterDescriptor(description=..., integer_range=[...] or '
                         'floating_point_range=[...]) as the third argument of declare_parameter')
    passed(want)


@judged
def param_refused(node: str, name: str, value: Any, reason: str = '') -> None:
    """Setting `name` to `value` is refused (with a reason naming `reason`), value kept."""
    from robot_lab.graph.api import param_get
    from robot_lab.graph.parameters import set_parameters

    full = '/' + node.lstrip('/')
    before = param_get(full, name)
    (result,) = set_parameters(full, {name: value})
    after = param_get(full, name)
    want = f'{full} to refuse {name} = {value!r}' + (f' with a reason about {reason}'
                                                      if reason else '')
    if result.successful:
        raise CheckError(want, 'it accepted it', 'in your on-set callback return '
                         "SetParametersResult(successful=False, reason='...') when the value "
                         'breaks the rule, before storing anything')
    if not result.reason:
        raise CheckError(want, 'it refused it without a reason',
                         "say why: SetParametersResult(successful=False, reason='…') — "
                         '`ros2 param set` prints the reason to whoever tried')
    if reason not in result.reason:
        raise CheckError(want, f'it refused it with the reason {result.reason!r}',
                         f'name {reason} in the reason: the rule is about it, and the '
                         'person setting the value needs to know which one to change')
    if not same_value(before, after):
        raise CheckError(want, f'it refused, but {name} changed from {before!r} to {after!r}',
                         'validate every value before you store any of them')
    passed(f'{full} refuses {name} = {value!r}: {result.reason}')


_NO_RESULT = 'Callback returned an invalid type'  # rclpy's reason when a callback returns None


def _refusal(name: str, value: Any, reason: str) -> tuple[str, str]:
    """(what was seen, what to try) when a set that breaks no rule is refused."""
    if reason == _NO_RESULT:
        return (f'it refused it: {reason!r} — your on-set callback returned no '
                'SetParametersResult (a missing return)',
                'end the callback with return SetParametersResult(successful=True), after '
                'storing the values')
    if not reason:
        return ('it refused it without a reason: your on-set callback returned a '
                'SetParametersResult whose successful is False (its default)',
                'accept with return SetParametersResult(successful=True); refuse '
                "(successful=False, reason='…') only a value that breaks your rule")
    return (f'it refused it: {reason}',
            f'{name} = {value!r} is in range and breaks no rule: check the condition in your '
            'on-set callback; it must refuse only the values that break the rule')


@judged
def param_applied(node: str, name: str, value: Any, topic: str,
                  where: Callable[[Any], bool], description: str,
                  timeout: float = 5.0) -> None:
    """Setting `name` to `value` is accepted and then `topic` carries a message `where` likes."""
    from robot_lab.graph.parameters import set_parameters

    full = '/' + node.lstrip('/')
    (result,) = set_parameters(full, {name: value})
    if not result.successful:
        raise CheckError(f'{full} to accept {name} = {value!r}',
                         *_refusal(name, value, result.reason or ''))
    try:
        topic_publishes(topic, where=where, timeout=timeout, description=description)
    except CheckError as err:
        raise CheckError(f'{name} = {value!r} to take effect: {topic} {description}',
                         err.seen, 'store the new value in your callback (self.… = '
                                   'param.value); reading it in __init__ only is not enough'
                         ) from None
