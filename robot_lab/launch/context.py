"""LaunchContext: what actions read and change while a description is executed.

Launch configurations, the environment, the ROS namespace, global parameters and remaps,
each with the scopes groups push and pop; and the plan being built (`sink`). Problems
are LaunchErrors located at the action being executed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import LaunchError, ParamFileError, RobotLabError
from robot_lab.launch.description import Action, LaunchArgument
from robot_lab.launch.substitutions import Substitution, SubstitutionFailure

if TYPE_CHECKING:
    from robot_lab.launch.action import DescriptionStep, LaunchStep

__all__ = ['LaunchContext']


def _no_loader(path: Path) -> DescriptionStep:
    raise LaunchError(f'cannot include {path}: this context has no launch file loader')


class LaunchContext:
    """The state actions read and change, with scopes pushed and popped by groups."""

    def __init__(self, arguments: Mapping[str, str], environment: Mapping[str, str]) -> None:
        self.configurations: dict[str, str] = dict(arguments)
        self.environment: dict[str, str] = dict(environment)
        self.initial_environment = dict(environment)
        # launch keeps these three in its launch configurations; so do we (scoped the same)
        self.ros: dict[str, Any] = {'ros_namespace': None, 'global_params': None,
                                    'ros_remaps': None}
        self._scopes: list[tuple[dict[str, str], dict[str, Any], dict[str, str]]] = []
        self.files: list[Path] = []
        self.sink: list[Action] = []
        self.arguments: list[LaunchArgument] = []
        self.source: tuple[Path | None, int | None] = (None, None)
        self._file_override: Path | None = None
        # how an include reads its file (describe.py sets it: actions never import frontends)
        self.load_description: Callable[[Path], DescriptionStep] = _no_loader

    # what substitutions and OpaqueFunctions see
    @property
    def current_file(self) -> Path | None:
        return self._file_override or (self.files[-1] if self.files else None)

    @property
    def launch_configurations(self) -> dict[str, str]:
        return self.configurations

    def perform_substitution(self, substitution: Substitution) -> str:
        return substitution.perform(self)

    def push(self) -> None:
        self._scopes.append((dict(self.configurations), dict(self.ros), dict(self.environment)))

    def pop(self) -> None:
        self.configurations, self.ros, self.environment = self._scopes.pop()

    def where(self) -> str | None:
        """'file:line' of the action being executed, for ProcessSpec.source and friends."""
        file, line = self.source
        if file is None:
            return None
        return str(file) if line is None else f'{file}:{line}'

    def error(self, message: str, fix: str | None = None) -> LaunchError:
        file, line = self.source
        return LaunchError(message, file=file, line=line, fix=fix)

    def run(self, actions: Iterable[LaunchStep]) -> None:
        for action in actions:
            self.run_one(action)

    def run_one(self, action: LaunchStep) -> None:
        previous, previous_file = self.source, self._file_override
        self.source = (action.file or self.current_file, action.line)
        self._file_override = action.file
        try:
            if action.condition is None or action.condition.evaluate(self):
                action.execute(self)
        except RobotLabError as err:
            if isinstance(err, LaunchError | ParamFileError) or err.file is not None:
                raise
            raise self.error(err.message, err.fix) from None
        except (SubstitutionFailure, ValueError, TypeError, RuntimeError, OSError) as err:
            raise self.error(str(err)) from None
        finally:
            self.source, self._file_override = previous, previous_file
