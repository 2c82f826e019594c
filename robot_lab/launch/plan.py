"""The one static launch description every frontend (XML, YAML, Python) produces.

A `LaunchPlan` is fully resolved: substitutions evaluated, conditions applied, includes
inlined, namespaces pushed, parameter files written. The supervisor only runs it, so a
launch file is checked completely before any process starts.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeAlias

from robot_lab.launch.events import EventKind

__all__ = [
    'Action',
    'EventHandlerSpec',
    'LaunchArgument',
    'LaunchPlan',
    'LifecycleRequest',
    'LogAction',
    'ProcessSpec',
    'ShutdownAction',
    'TimerSpec',
]


@dataclass
class ProcessSpec:
    """One process to start: a node (`node_name` set) or a plain executable."""

    cmd: list[str]
    label: str
    env: dict[str, str]
    cwd: str | None = None
    output: str = 'log'
    respawn: bool = False
    respawn_delay: float = 0.0
    respawn_max_retries: int = -1
    on_exit: str | None = None
    sigterm_timeout: float = 5.0
    sigkill_timeout: float = 5.0
    shell: bool = False
    node_name: str | None = None
    package: str | None = None
    executable: str = ''
    param_files: list[str] = field(default_factory=list)
    source: str | None = None
    origin: object = field(default=None, repr=False)  # the action it came from (event targets)
    lifecycle: str | None = None  # a LifecycleNode: 'manual' or 'autostart'


@dataclass
class LogAction:
    """`<log message=...>` / LogInfo: a line the launcher itself logs."""

    message: str
    level: str = 'INFO'
    source: str | None = None


@dataclass
class TimerSpec:
    """A resolved `<timer>`/TimerAction: its actions, started `period` seconds after launch."""

    period: float
    actions: list[Action]
    source: str | None = None


@dataclass
class ShutdownAction:
    """`<shutdown>` / Shutdown(): ends the whole launch."""

    reason: str = ''
    source: str | None = None


@dataclass
class EventHandlerSpec:
    """RegisterEventHandler: when `event` happens to a process of `target` (None: any),
    `respond(event)` resolves the handler's actions then, in the context they were
    registered in, and the supervisor runs what it returns."""

    event: EventKind
    target: object  # an action, a matcher function of one, or None: any
    respond: Callable[[object], list[Action]] = field(repr=False)
    description: str = ''
    source: str | None = None

    def matches(self, origin: object) -> bool:
        if self.target is None:
            return True
        if callable(self.target) and not hasattr(self.target, 'execute'):
            return bool(self.target(origin))  # a matcher function, as launch allows
        return self.target is origin


@dataclass
class LifecycleRequest:
    """EmitEvent(ChangeState(...)): the matching lifecycle nodes should take a transition."""

    matcher: Callable[[object], bool] = field(repr=False)
    transition_id: int
    source: str | None = None


Action: TypeAlias = (ProcessSpec | LogAction | TimerSpec | ShutdownAction | EventHandlerSpec
                     | LifecycleRequest)


@dataclass
class LaunchArgument:
    """A declared launch argument (`<arg>` / DeclareLaunchArgument), for `--show-args`."""

    name: str
    default: str | None
    description: str = ''
    choices: list[str] | None = None


@dataclass
class LaunchPlan:
    """Everything one launch file asks for, in order."""

    source: Path
    actions: list[Action]
    arguments: list[LaunchArgument]
    log_dir: Path | None = None  # made while resolving ($(log_dir)); the output uses it

    def processes(self) -> list[ProcessSpec]:
        """Every process, including those inside timers, in start order."""
        found: list[ProcessSpec] = []

        def walk(actions: list[Action]) -> None:
            for action in actions:
                if isinstance(action, ProcessSpec):
                    found.append(action)
                elif isinstance(action, TimerSpec):
                    walk(action.actions)

        walk(self.actions)
        return found
