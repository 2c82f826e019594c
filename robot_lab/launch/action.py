"""The base of every launch action, and what actions share: substitutions in, location.

Like ros2/launch this runs in two phases: a frontend (XML, YAML or Python) *parses* a
file into actions (so an unknown tag or attribute anywhere is an error, even in a branch
that is switched off), then the actions are *executed* against a LaunchContext (see
context.py). Executing a process action does not start it: it resolves its command line
into a ProcessSpec of the plan.
"""

from __future__ import annotations

import inspect
import os
import sysconfig
import traceback
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, TypeAlias

from robot_lab.errors import LaunchError
from robot_lab.launch.substitutions import SomeSubstitutions, Substitution, Text

if TYPE_CHECKING:
    from robot_lab.launch.conditions import Condition
    from robot_lab.launch.context import LaunchContext

__all__ = ['HasEntities', 'LaunchDescriptionStep', 'LaunchEntity', 'LaunchStep', 'Subs',
           'as_step', 'caller_line', 'opt_subs', 'python_error', 'subs']

Subs = list[Substitution]


def subs(value: SomeSubstitutions) -> Subs:
    """SomeSubstitutionsType (str, Substitution or a list of them) -> list of substitutions."""
    if isinstance(value, Substitution):
        return [value]
    if isinstance(value, str):
        return [Text(value)]
    if isinstance(value, os.PathLike):
        return [Text(os.fspath(value))]
    if isinstance(value, Iterable):
        out: Subs = []
        for item in value:
            out.extend(subs(item))
        return out
    raise TypeError(f'expected text or substitutions, got {type(value).__name__}: {value!r}')


def opt_subs(value: SomeSubstitutions | None) -> Subs | None:
    return None if value is None else subs(value)


def caller_line() -> tuple[Path | None, int | None]:
    """file:line of the first frame outside robot_lab's launch package (a Python launch file).

    Import machinery frames (`<frozen importlib._bootstrap>`, which runs a facade's
    `__getattr__` for `from launch import X`) are skipped too: the line is the import's."""
    here = str(Path(__file__).parent)
    for frame in inspect.stack(0)[2:]:
        if not frame.filename.startswith((here, '<frozen ')):
            return Path(frame.filename), frame.lineno
    return None, None


class LaunchStep:
    """A parsed action; `execute` resolves it into the plan (and may change the context)."""

    file: Path | None = None
    line: int | None = None
    condition: Condition | None = None
    launch_name = 'Action'  # what launch calls it (for --print)
    runs_children_later = False  # a timer's or handler's actions: not part of this scope now

    def locate(self, file: Path | None, line: int | None) -> None:
        self.file, self.line = file, line

    def locate_caller(self) -> None:
        self.file, self.line = caller_line()

    def execute(self, context: LaunchContext) -> None:
        raise NotImplementedError

    def children(self) -> list[LaunchStep]:
        return []


class LaunchDescriptionStep(LaunchStep):
    """A LaunchDescription: its entities, in order, in the current scope."""

    launch_name = 'LaunchDescription'

    def __init__(self, entities: Sequence[LaunchStep]) -> None:
        self.entities = list(entities)

    def execute(self, context: LaunchContext) -> None:
        context.run(self.entities)

    def children(self) -> list[LaunchStep]:
        return self.entities


class HasEntities(Protocol):
    """launch's LaunchDescription as an action sees it (the Python API's, or a look-alike)."""

    @property
    def entities(self) -> Sequence[LaunchEntity]: ...


# What a Python launch file may put where launch wants an action.
LaunchEntity: TypeAlias = 'LaunchStep | HasEntities'


def python_error(err: BaseException, what: str) -> LaunchError:
    """A Python exception from launch-file code, located at its innermost launch-file frame."""
    frames = traceback.extract_tb(err.__traceback__)
    kit = str(Path(__file__).parents[1])  # robot_lab/: the kit's own frames are not the cause
    library = (sysconfig.get_paths()['stdlib'], 'site-packages')
    located = [f for f in frames if not f.filename.startswith(kit)
               and not any(part in f.filename for part in library)] or \
        [f for f in frames if not f.filename.startswith(str(Path(__file__).parent))]
    frame = located[-1] if located else (frames[-1] if frames else None)
    file, line = (frame.filename, frame.lineno) if frame else (None, None)
    missing = getattr(err, 'name', None) if isinstance(err, ModuleNotFoundError) else None
    if missing and missing.split('.')[0] in ('launch', 'launch_ros', 'launch_xml',
                                             'launch_yaml'):
        return LaunchError(
            f"{missing} is not provided by robot_lab's launcher", file=file, line=line,
            fix='run this file with a full ROS 2 install (ros2 launch), or do without it')
    return LaunchError(f'{what} raised {type(err).__name__}: {err}', file=file, line=line)


def as_step(item: object) -> LaunchStep:
    if isinstance(item, LaunchStep):
        return item
    entities = getattr(item, 'entities', None)
    if entities is not None:
        return LaunchDescriptionStep([as_step(e) for e in entities])
    raise TypeError(f'not a launch action: {item!r}')
