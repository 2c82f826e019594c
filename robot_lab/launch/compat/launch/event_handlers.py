"""launch.event_handlers: OnProcessStart, OnProcessExit, OnProcessIO, OnExecutionComplete,
OnShutdown (with launch's keyword arguments)."""

from __future__ import annotations

from typing import NoReturn

from robot_lab.launch.actions.event_handlers import EventHandler, Response
from robot_lab.launch.compat_path import unsupported

__all__ = [
    'EventHandler',
    'OnExecutionComplete',
    'OnProcessExit',
    'OnProcessIO',
    'OnProcessStart',
    'OnShutdown',
]


class OnProcessStart(EventHandler):
    launch_name = 'OnProcessStart'

    def __init__(self, *, target_action: object = None, on_start: Response, **_: object) -> None:
        super().__init__('process_start', target_action, {'on_start': on_start})


class OnProcessExit(EventHandler):
    launch_name = 'OnProcessExit'

    def __init__(self, *, target_action: object = None, on_exit: Response, **_: object) -> None:
        super().__init__('process_exit', target_action, {'on_exit': on_exit})


class OnProcessIO(EventHandler):
    launch_name = 'OnProcessIO'

    def __init__(self, *, target_action: object = None, on_stdin: Response = None,
                 on_stdout: Response = None, on_stderr: Response = None, **_: object) -> None:
        # on_stdin: the kit's processes never read stdin, so there is nothing to report
        super().__init__('process_io', target_action,
                         {'on_stdout': on_stdout, 'on_stderr': on_stderr}, pass_context=False)


class OnExecutionComplete(EventHandler):
    launch_name = 'OnExecutionComplete'

    def __init__(self, *, target_action: object = None, on_completion: Response,
                 **_: object) -> None:
        super().__init__('execution_complete', target_action, {'on_completion': on_completion})


class OnShutdown(EventHandler):
    launch_name = 'OnShutdown'

    def __init__(self, *, on_shutdown: Response, **_: object) -> None:
        super().__init__('shutdown', None, {'on_shutdown': on_shutdown})


def __getattr__(name: str) -> NoReturn:
    raise unsupported('launch.event_handlers', name, __all__)
