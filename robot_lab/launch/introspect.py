"""`ros2 launch --print`: the parsed description as a tree, with nothing evaluated.

Like launch's LaunchIntrospector this only looks at the actions a frontend built: no
substitution is performed, no package looked up, no parameter file written, no required
argument needed. Each action shows its launch name and its arguments; substitutions show
as what they would read (`LaunchConfiguration('robot_name')`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

from robot_lab.launch.action import LaunchStep
from robot_lab.launch.substitutions import Substitution

__all__ = ['describe_value', 'format_description']

_SKIP = {'file', 'line', 'condition', 'loader', 'options'}


def describe_value(value: object) -> str:
    """A value of an action as --print shows it; substitutions are never performed."""
    if isinstance(value, Substitution):
        return value.describe()
    if isinstance(value, list) and value and all(isinstance(v, Substitution) for v in value):
        return ' + '.join(v.describe() for v in value)
    if isinstance(value, LaunchStep):
        return _name(value)
    if isinstance(value, dict):
        return '{' + ', '.join(f'{describe_value(k)}: {describe_value(v)}'
                               for k, v in value.items()) + '}'
    if isinstance(value, list | tuple):
        return '[' + ', '.join(describe_value(v) for v in value) + ']'
    if type(value).__name__ in ('ParamValue', 'ParameterValue'):
        return describe_value(getattr(value, 'value', None))
    if hasattr(value, '__dataclass_fields__'):
        fields = ', '.join(f'{k}={describe_value(v)}' for k, v in vars(value).items()
                           if v not in (None, [], {}))
        return f'{type(value).__name__}({fields})'
    describe = getattr(value, 'describe', None)
    if callable(describe) and hasattr(value, 'responses'):  # an event handler
        return str(describe())
    if callable(value):
        return getattr(value, '__qualname__', repr(value))
    return repr(value)


def _name(step: LaunchStep) -> str:
    return getattr(step, 'launch_name', None) or type(step).__name__


def _line(step: LaunchStep) -> str:
    children = {id(c) for c in step.children()}
    parts = []
    for key, value in vars(step).items():
        if key.startswith('_') or key in _SKIP or value is None or value == [] or \
                value == {}:
            continue
        if isinstance(value, list) and value and all(id(v) in children for v in value):
            continue  # shown below as the tree
        parts.append(f'{key}={describe_value(value)}')
    options = getattr(step, 'options', None)
    if options is not None:
        defaults = type(options)()
        parts += [f'{k}={describe_value(v)}' for k, v in vars(options).items()
                  if v != getattr(defaults, k) and v not in (None, [])]
    if step.condition is not None:
        parts.append(f'condition={step.condition.describe()}')
    where = f'  # {Path(step.file).name}:{step.line}' if step.file and step.line else ''
    return f'{_name(step)}({", ".join(parts)}){where}'


Expand = Callable[[LaunchStep], tuple[Path, LaunchStep] | None]


def format_description(root: LaunchStep, source: Path, expand: Expand | None = None) -> str:
    """The whole tree: `LaunchDescription <file>`, then one line per action.

    `expand` gives an include's own description when its file is known without a launch
    context (a literal path, `get_package_share_directory(...)`): it is shown under the
    include, as launch's introspector shows it. Other includes stay unexpanded.
    """
    lines = [f'LaunchDescription {source}']
    files = [source.resolve()]

    def walk(steps: Iterable[LaunchStep], prefix: str) -> None:
        items: list[LaunchStep | tuple[Path, LaunchStep]] = list(steps)
        for index, item in enumerate(items):
            last = index == len(items) - 1
            branch = prefix + ('└── ' if last else '├── ')
            inner = prefix + ('    ' if last else '│   ')
            if isinstance(item, tuple):  # an included file
                path, description = item
                lines.append(f'{branch}LaunchDescription {path}')
                files.append(path.resolve())
                walk(description.children(), inner)
                files.pop()
                continue
            lines.append(branch + _line(item))
            children: list[LaunchStep | tuple[Path, LaunchStep]] = list(item.children())
            included = expand(item) if expand is not None else None
            if included is not None and included[0].resolve() not in files:
                children.append(included)
            walk(children, inner)  # type: ignore[arg-type]

    walk(root.children(), '')
    return '\n'.join(lines)
