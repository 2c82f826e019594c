"""Starting and stopping one child: forked or exec'd, its exit fd, launch's signal escalation.

The supervisor decides when a process starts, respawns or stops; how is here: the fork
server takes a Python node it can run, anything else is exec'd by `robot_lab.process.spawn`
(from the supervisor's thread, which its parent-death signal is tied to), and a stop is
launch's SIGINT, then SIGTERM, then SIGKILL, worded as launch words it.
"""

from __future__ import annotations

import contextlib
import signal
import subprocess
from collections.abc import Callable
from typing import TypeAlias

from robot_lab.launch.fork_client import ForkedProcess, ForkServer
from robot_lab.launch.output import LaunchOutput
from robot_lab.launch.plan import ProcessSpec
from robot_lab.launch.process_record import ProcessRecord
from robot_lab.linux.pidfd import open_pidfd
from robot_lab.process import spawn

__all__ = ['exit_fd', 'kill_leftovers', 'send_signal', 'start_child', 'stop_process']

Child: TypeAlias = subprocess.Popen[bytes] | ForkedProcess  # what a started child is


def start_child(spec: ProcessSpec, env: dict[str, str], forks: ForkServer | None,
                interpreter: str | None) -> Child:
    """Forked by the fork server when it takes the node, else exec'd; OSError if neither."""
    popen: Child | None = None
    if forks is not None and interpreter is not None:
        popen = forks.start(spec, env, spec.cwd, interpreter)
    if popen is None:
        popen = spawn(spec.cmd, env=env, cwd=spec.cwd,
                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, shell=spec.shell)
    return popen


def exit_fd(popen: Child) -> int | None:
    """A pidfd readable once an exec'd child exits; None for a forked node (its exit comes
    from the fork server) or when there is no pidfd (or the child is gone already): its
    exit is then polled."""
    if isinstance(popen, ForkedProcess):
        return None
    with contextlib.suppress(OSError):
        return open_pidfd(popen.pid)
    return None


def _seconds(value: float) -> str:
    """A timeout as launch prints it: '5' for the default, '0.5' otherwise."""
    return f'{value:g}'


def stop_process(record: ProcessRecord, output: LaunchOutput, *, send_sigint: bool,
                 later: Callable[[float, Callable[[], None]], object]) -> None:
    """SIGINT now, SIGTERM after sigterm_timeout, SIGKILL after sigkill_timeout more.

    `later(delay, callback)` schedules a callback that does not keep the launch alive."""
    record.stopping = True
    spec = record.spec
    generation = record.generation
    base = ("process[{}] failed to terminate '{}' seconds after receiving '{}', "
            "escalating to '{}'")

    def escalate(sig: signal.Signals, previous: str, waited: str) -> None:
        if record.state != 'running' or record.generation != generation:
            return
        output.launcher(
            'ERROR', record.label, base.format(record.label, waited, previous, sig.name))
        send_signal(record, sig, output)

    later(spec.sigterm_timeout,
          lambda: escalate(signal.SIGTERM, 'SIGINT', _seconds(spec.sigterm_timeout)))
    total = float(spec.sigterm_timeout) + float(spec.sigkill_timeout)
    later(total, lambda: escalate(signal.SIGKILL, 'SIGTERM', str(total)))
    if send_sigint:
        send_signal(record, signal.SIGINT, output)


def send_signal(record: ProcessRecord, sig: signal.Signals, output: LaunchOutput) -> None:
    popen = record.popen
    if popen is None or popen.poll() is not None:
        return
    output.launcher('INFO', record.label,
                    f"sending signal '{sig.name}' to process[{record.label}]")
    with contextlib.suppress(ProcessLookupError):
        popen.send_signal(sig)


def kill_leftovers(records: list[ProcessRecord]) -> None:
    """Only reached on an error inside the loop: never leave a child behind."""
    for record in records:
        if record.popen is not None and record.popen.poll() is None:
            record.popen.kill()
            record.popen.wait()
            record.state, record.returncode = 'died', record.popen.returncode
