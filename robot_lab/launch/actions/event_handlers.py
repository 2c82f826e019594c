"""RegisterEventHandler with OnProcessStart/OnProcessExit/OnProcessIO/OnExecutionComplete/
OnShutdown, and EmitEvent(event=Shutdown()) — Python launch files only, as in launch.

The plan is resolved before anything starts, but a handler's actions must see the event:
so registering a handler puts an EventHandlerSpec into the plan holding a snapshot of the
context, and the supervisor asks it to resolve the actions when the event happens.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, TypeAlias

from robot_lab.errors import RobotLabError
from robot_lab.launch.action import LaunchEntity, LaunchStep, as_step, python_error
from robot_lab.launch.compat_path import compat_api
from robot_lab.launch.events import ChangeState, EventKind, Shutdown
from robot_lab.launch.plan import (
    Action,
    EventHandlerSpec,
    LifecycleRequest,
    ShutdownAction,
)
from robot_lab.launch.substitutions import perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['EmitEventStep', 'EventHandler', 'HandlerFunction', 'RegisterEventHandlerStep',
           'Response']

# what each handler's callable receives: (event, context), except OnProcessIO's (event)
HandlerFunction: TypeAlias = Callable[..., 'LaunchEntity | Sequence[LaunchEntity] | None']
Response: TypeAlias = 'LaunchEntity | Sequence[LaunchEntity] | HandlerFunction | None'


class EventHandler:
    """launch.event_handlers.*: which event, of which action, answered by what."""

    launch_name = 'EventHandler'

    def __init__(self, event: EventKind, target: object, responses: dict[str, Response],
                 pass_context: bool = True,
                 accepts: Callable[[object], bool] | None = None) -> None:
        self.event, self.target, self.pass_context = event, target, pass_context
        self.accepts = accepts  # a further filter on the event (OnStateTransition's states)
        self.responses = {key: value for key, value in responses.items() if value is not None}
        # a static list of actions is parsed now (a mistake in it fails before anything runs)
        self.steps: dict[str, list[LaunchStep]] = {
            key: [as_step(a) for a in (value if isinstance(value, list | tuple) else [value])]
            for key, value in self.responses.items() if not _is_function(value)}

    def children(self) -> list[LaunchStep]:
        return [step for steps in self.steps.values() for step in steps]

    def describe(self) -> str:
        target = '' if self.target is None else \
            f'target_action={getattr(self.target, "launch_name", type(self.target).__name__)}'
        functions = [f'{key}={getattr(value, "__qualname__", "function")}'
                     for key, value in self.responses.items() if key not in self.steps]
        return f'{self.launch_name}({", ".join(p for p in (target, *functions) if p)})'

    def respond(self, event: object, registered: LaunchContext) -> list[Action]:
        """The actions this event asks for, resolved in a copy of the registering context."""
        context = registered.snapshot()
        context.locals.event = event
        context.sink = []
        key = self._response_key(event)
        if key is None or (self.accepts is not None and not self.accepts(event)):
            return []
        if key in self.steps:
            steps = self.steps[key]
        else:
            function = self.responses[key]
            assert callable(function)
            try:
                with compat_api():
                    result = function(event, context) if self.pass_context else function(event)
            except RobotLabError:
                raise
            except Exception as err:
                raise python_error(err, f'{self.launch_name} {key}') from None
            if result is None:
                return []
            items = result if isinstance(result, list | tuple) else [result]
            steps = [as_step(item) for item in items]
        context.run(steps)
        return context.sink

    def _response_key(self, event: object) -> str | None:
        if self.event == 'process_io':
            wanted = 'on_stdout' if getattr(event, 'fd', 1) == 1 else 'on_stderr'
            return wanted if wanted in self.responses else None
        return next(iter(self.responses), None)


def _is_function(value: object) -> bool:
    return callable(value) and not isinstance(value, LaunchStep) and \
        not hasattr(value, 'entities')


class RegisterEventHandlerStep(LaunchStep):
    """RegisterEventHandler(handler): from here on, the handler answers its events."""

    launch_name = 'RegisterEventHandler'
    runs_children_later = True

    def __init__(self, handler: EventHandler) -> None:
        if not isinstance(handler, EventHandler):
            raise TypeError(f'RegisterEventHandler expects an event handler such as '
                            f'OnProcessExit(...), got {type(handler).__name__}')
        self.handler = handler

    def children(self) -> list[LaunchStep]:
        return self.handler.children()

    def execute(self, context: LaunchContext) -> None:
        handler, registered = self.handler, context.snapshot()
        context.sink.append(EventHandlerSpec(
            handler.event, handler.target,
            lambda event: handler.respond(event, registered),
            description=handler.describe(), source=context.where()))


class EmitEventStep(LaunchStep):
    """EmitEvent(event=Shutdown(reason=...)): the one event a launch file emits here."""

    launch_name = 'EmitEvent'

    def __init__(self, event: object) -> None:
        if not isinstance(event, Shutdown | ChangeState):
            raise TypeError(
                'robot_lab can emit launch.events.Shutdown and launch_ros.events.lifecycle.'
                f'ChangeState, not {type(event).__name__}')
        self.event = event

    def execute(self, context: LaunchContext) -> None:
        if isinstance(self.event, ChangeState):
            context.sink.append(LifecycleRequest(
                self.event.lifecycle_node_matcher, int(self.event.transition_id),
                source=context.where()))
            return
        reason: Any = self.event.reason
        text = reason if isinstance(reason, str) else perform(reason, context)
        context.sink.append(ShutdownAction(text, source=context.where()))
