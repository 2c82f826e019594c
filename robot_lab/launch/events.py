"""Launch events: what the supervisor reports to event handlers, as launch names them.

`launch.events.process.ProcessStarted/ProcessExited/ProcessIO`,
`launch.events.ExecutionComplete` and `launch.events.Shutdown` carry the same attributes
here, so an `on_exit=lambda event, context: ...` or `LocalSubstitution('event.reason')`
written for ROS 2 reads them unchanged.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

__all__ = [
    'ChangeState',
    'EventKind',
    'ExecutionComplete',
    'ProcessEvent',
    'ProcessExited',
    'ProcessIO',
    'ProcessStarted',
    'Shutdown',
    'StateTransition',
    'matches_action',
]

EventKind = Literal['process_start', 'process_exit', 'process_io', 'execution_complete',
                    'shutdown', 'state_transition']


@dataclass
class ProcessEvent:
    """What every process event tells: which action, which process."""

    action: object  # the ExecuteProcess/Node action the process came from
    name: str  # its label, `sensor_node-1`
    cmd: list[str]
    cwd: str | None
    env: dict[str, str] = field(repr=False)
    pid: int

    @property
    def process_name(self) -> str:
        """launch's RunningProcessEvent.process_name (launch's own counters example prints it)."""
        return self.name

    @property
    def execute_process_action(self) -> object:
        return self.action


@dataclass
class ProcessStarted(ProcessEvent):
    """launch.events.process.ProcessStarted."""


@dataclass
class ProcessExited(ProcessEvent):
    """launch.events.process.ProcessExited."""

    returncode: int = 0


@dataclass
class ProcessIO(ProcessEvent):
    """launch.events.process.ProcessIO: one line of output (`text` ends with a newline)."""

    text: bytes = b''
    fd: int = 1

    @property
    def from_stdin(self) -> bool:
        return self.fd == 0

    @property
    def from_stdout(self) -> bool:
        return self.fd == 1

    @property
    def from_stderr(self) -> bool:
        return self.fd == 2


@dataclass
class ExecutionComplete:
    """launch.events.ExecutionComplete: an action (here: a process) has finished."""

    action: object


@dataclass
class Shutdown:
    """launch.events.Shutdown: the launch is asked to end (EmitEvent(event=Shutdown()))."""

    reason: str = 'reason not given'
    due_to_sigint: bool = False


@dataclass
class ChangeState:
    """launch_ros.events.lifecycle.ChangeState: ask matching lifecycle nodes to transition."""

    # a function of the action (launch.events.matches_action)
    lifecycle_node_matcher: Callable[[object], bool]
    transition_id: int


@dataclass
class StateTransition:
    """launch_ros.events.lifecycle.StateTransition: a lifecycle node changed state."""

    action: object
    msg: object  # the lifecycle_msgs/msg/TransitionEvent
    transition: str
    start_state: str
    goal_state: str


def matches_action(target: object) -> Callable[[object], bool]:
    """launch.events.matches_action: a matcher for events about `target`."""
    return lambda action: action is target
