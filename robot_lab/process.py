"""Child processes that cannot outlive their parent, even after `kill -9` of the parent.

Every node robot_lab starts (launch, kernel, tests) goes through `spawn`: the child asks
the kernel (prctl PR_SET_PDEATHSIG) to be killed when its parent dies, and gets default
SIGINT/SIGTERM dispositions back (a parent started with `&` passes SIGINT on ignored).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

from robot_lab.linux import capabilities
from robot_lab.linux.libc import libc
from robot_lab.linux.prctl import set_parent_death_signal

__all__ = ['child_setup', 'spawn', 'stop']


def child_setup() -> None:
    """`preexec_fn` for a child that dies with this process and takes Ctrl-C as a fresh
    process does, even when this one was started with SIGINT ignored (`cmd &`, nohup)."""
    # Runs in the child between fork and exec: only async-signal-safe work here (the C
    # library was loaded by spawn() before the fork: no lock taken here).
    armed = set_parent_death_signal(signal.SIGKILL)
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if armed and os.getppid() == 1:
        os._exit(1)  # the parent died before prctl took effect


# Loaded now, before any fork: child_setup, between fork and exec, may not load it.
with contextlib.suppress(OSError):
    libc()


def spawn(
    cmd: Sequence[str],
    *,
    env: Mapping[str, str] | None = None,
    cwd: str | Path | None = None,
    stdout: int | IO[Any] | None = subprocess.PIPE,
    stderr: int | IO[Any] | None = subprocess.STDOUT,
    shell: bool = False,
    pass_fds: Sequence[int] = (),
    stdin: int | IO[Any] | None = subprocess.DEVNULL,
) -> subprocess.Popen[bytes]:
    """Start `cmd`; it dies with this process (SIGKILL) if this process dies first. The
    capabilities switched off here (`linux.capabilities.switched_off`) are off in it too.

    The parent-death signal fires when the *thread* that forked exits, so call this from
    the main thread or a thread that lives as long as the child should.
    """
    return subprocess.Popen(
        list(cmd) if not shell else ' '.join(cmd),
        env=capabilities.child_environment(os.environ if env is None else env),
        cwd=cwd,
        stdin=stdin,
        stdout=stdout,
        stderr=stderr,
        shell=shell,
        pass_fds=tuple(pass_fds),
        preexec_fn=child_setup,
    )


def stop(
    proc: subprocess.Popen[Any], sigint_timeout: float = 5.0, sigterm_timeout: float = 5.0
) -> int:
    """SIGINT, then SIGTERM, then SIGKILL, waiting between steps; returns the exit code."""
    for sig, timeout in ((signal.SIGINT, sigint_timeout), (signal.SIGTERM, sigterm_timeout)):
        if proc.poll() is not None:
            break
        proc.send_signal(sig)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            continue
    if proc.poll() is None:
        proc.kill()
    return proc.wait()
