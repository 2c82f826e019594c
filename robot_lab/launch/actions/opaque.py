"""OpaqueFunction (Python launch files only): a function run with the context."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, TypeAlias

from robot_lab.errors import RobotLabError
from robot_lab.launch.action import LaunchEntity, LaunchStep, as_step, python_error
from robot_lab.launch.compat_path import compat_api

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['OpaqueCallable', 'OpaqueStep']

# function(context, *args, **kwargs) -> the actions to run in its place (or None)
OpaqueCallable: TypeAlias = Callable[..., 'Sequence[LaunchEntity] | None']


class OpaqueStep(LaunchStep):
    """OpaqueFunction: called with the context; the actions it returns run in place."""

    launch_name = 'OpaqueFunction'

    def __init__(self, function: OpaqueCallable, args: Sequence[object] | None = None,
                 kwargs: Mapping[str, object] | None = None) -> None:
        self.function, self.args, self.kwargs = function, list(args or []), dict(kwargs or {})

    def execute(self, context: LaunchContext) -> None:
        try:
            with compat_api():  # the function may import launch modules or look up packages
                result = self.function(context, *self.args, **self.kwargs)
        except RobotLabError:
            raise
        except Exception as err:
            raise python_error(err, 'OpaqueFunction') from None
        if result:
            context.run([as_step(item) for item in result])
