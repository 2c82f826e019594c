"""The one way a LaunchPlan runs: a Supervisor driven to the end in the calling thread.

The CLI calls it in its main thread (Ctrl-C and SIGTERM stop the launch in order); the
notebook handle calls it in the background thread its children's parent-death signal is
tied to (no signal handlers there: the kernel owns them).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from types import FrameType

from robot_lab.launch.supervisor import Supervisor

__all__ = ['run_supervisor']


def run_supervisor(supervisor: Supervisor, *,
                   on_start: Callable[[Supervisor], None] | None = None) -> int:
    """Open the output, run until every process has ended, close it; the exit code.

    In the main thread SIGINT/SIGTERM are routed to the supervisor for the duration and
    restored afterwards.
    """
    previous: dict[signal.Signals, object] = {}
    if threading.current_thread() is threading.main_thread():

        def on_sigint(signum: int, frame: FrameType | None) -> None:
            supervisor.interrupt()

        def on_sigterm(signum: int, frame: FrameType | None) -> None:
            supervisor.terminate()

        previous = {
            signal.SIGINT: signal.signal(signal.SIGINT, on_sigint),
            signal.SIGTERM: signal.signal(signal.SIGTERM, on_sigterm),
        }
    supervisor.output.open()
    try:
        if on_start is not None:
            on_start(supervisor)
        return supervisor.run()
    finally:
        supervisor.output.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]
