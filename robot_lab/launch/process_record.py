"""The supervisor's bookkeeping: one ProcessRecord per process, scheduled callbacks."""

from __future__ import annotations

import subprocess
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from robot_lab.launch.fork_client import ForkedProcess
from robot_lab.launch.plan import ProcessSpec

__all__ = ['ProcessRecord', 'ProcessState', 'Scheduled', 'domain_of']

ProcessState = Literal['pending', 'running', 'finished', 'died', 'respawning']


def domain_of(env: dict[str, str]) -> int:
    """The ROS_DOMAIN_ID a process with this environment joins."""
    value = env.get('ROS_DOMAIN_ID', '').strip()
    return int(value) if value.isdigit() else 0


@dataclass
class ProcessRecord:
    """The live state of one ProcessSpec (a respawned process keeps its record)."""

    spec: ProcessSpec
    state: ProcessState = 'pending'
    pid: int | None = None
    returncode: int | None = None
    retries: int = 0
    popen: subprocess.Popen[bytes] | ForkedProcess | None = field(default=None, repr=False)
    generation: int = 0
    stopping: bool = False
    partial: dict[str, bytes] = field(default_factory=dict, repr=False)
    open_streams: int = 0
    pidfd: int | None = None
    graph: Path | None = None  # the graph_dir() of the node's environment

    @property
    def label(self) -> str:
        return self.spec.label

    @property
    def name(self) -> str:
        """The node's full name when it is a node (`/sensor`), else the label."""
        return self.spec.node_name or self.spec.label


@dataclass(order=True)
class Scheduled:
    """A callback of the supervisor's loop, due at a monotonic time."""

    due: float
    seq: int
    callback: Callable[[], None] = field(compare=False)
    keeps_alive: bool = field(compare=False, default=True)
    cancelled: bool = field(compare=False, default=False)
