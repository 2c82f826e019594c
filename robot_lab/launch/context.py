"""LaunchContext: what actions read and change while a description is executed.

Launch configurations, the environment, the ROS namespace, global parameters and remaps,
each with the scopes groups push and pop; and the plan being built (`sink`). Problems
are LaunchErrors located at the action being executed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from robot_lab.errors import LaunchError, ParamFileError, RobotLabError
from robot_lab.launch.output import make_log_dir
from robot_lab.launch.plan import Action, LaunchArgument
from robot_lab.launch.substitutions import Substitution, SubstitutionFailure

if TYPE_CHECKING:
    from robot_lab.launch.action import LaunchDescriptionStep, LaunchStep

__all__ = ['LaunchContext']


def _no_loader(path: Path) -> LaunchDescriptionStep:
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
        self._scopes: list[tuple[str, dict[str, str], dict[str, Any], dict[str, str]]] = []
        self.files: list[Path] = []
        self.sink: list[Action] = []
        self.arguments: list[LaunchArgument] = []
        self.source: tuple[Path | None, int | None] = (None, None)
        self._file_override: Path | None = None
        # how an include reads its file (describe.py sets it: actions never import frontends)
        self.load_launch_file: Callable[[Path], LaunchDescriptionStep] = _no_loader
        # what LocalSubstitution and event-handler functions read (`event` while handling one)
        self.locals = SimpleNamespace()
        self.made_log_dir: Path | None = None

    # what substitutions and OpaqueFunctions see
    @property
    def current_file(self) -> Path | None:
        return self._file_override or (self.files[-1] if self.files else None)

    @property
    def launch_configurations(self) -> dict[str, str]:
        return self.configurations

    def perform_substitution(self, substitution: Substitution) -> str:
        return substitution.perform(self)

    def log_dir(self) -> Path:
        """`$(log_dir)`: the launch's log directory, made on first use (the plan keeps it)."""
        if self.made_log_dir is None:
            self.made_log_dir = make_log_dir()
        return self.made_log_dir

    def snapshot(self) -> LaunchContext:
        """A copy that later changes to either side do not reach (for deferred actions)."""
        copy = LaunchContext(self.configurations, self.environment)
        copy.initial_environment = dict(self.initial_environment)
        copy.ros = {key: list(value) if isinstance(value, list) else value
                    for key, value in self.ros.items()}
        copy.files = list(self.files)
        copy.source, copy._file_override = self.source, self._file_override
        copy.load_launch_file = self.load_launch_file
        copy.locals = SimpleNamespace(**vars(self.locals))
        copy.made_log_dir = self.made_log_dir
        return copy

    def push(self, what: str = 'all') -> None:
        """A scope (group: 'all'; Push*Configurations/Environment: one of them)."""
        self._scopes.append((what, dict(self.configurations), dict(self.ros),
                             dict(self.environment)))

    def pop(self, what: str = 'all') -> None:
        kinds = [kind for kind, *_ in self._scopes]
        if what not in kinds:
            raise self.error(f'Pop{what.capitalize()} without a matching Push',
                             fix='pair every Pop... with a Push... before it')
        index = len(kinds) - 1 - kinds[::-1].index(what)
        _, configurations, ros, environment = self._scopes.pop(index)
        if what in ('all', 'configurations'):
            self.configurations, self.ros = configurations, ros
        if what in ('all', 'environment'):
            self.environment = environment

    @contextmanager
    def located(self, where: tuple[Path, int | None] | None) -> Iterator[None]:
        """Errors inside are located at `where` (a `<param>` inside its `<node>`)."""
        if where is None:
            yield
            return
        try:
            yield
        except (SubstitutionFailure, ValueError, TypeError, OSError) as err:
            raise LaunchError(str(err), file=where[0], line=where[1]) from None

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
