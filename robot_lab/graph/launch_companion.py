"""What a running launch does for graph queries: announce its nodes, keep a daemon warm.

A launcher tells graph queries which nodes it has up or is starting, one announcement
file per graph its nodes are in (expected.py), so `node list` waits for them; and, when
asked, it starts a graph daemon beside them (daemon.py) so one-shot CLI queries answer at
once. The launcher's supervisor only reports its processes here (graph, name, pid); it
knows nothing of files and sockets. Moved out of robot_lab/launch/supervisor.py as is.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from robot_lab.graph.expected import LaunchAnnouncement, graph_dir

if TYPE_CHECKING:
    from robot_lab.graph.daemon import Listener

__all__ = ['DAEMON_CHECK', 'DAEMON_NICE', 'LaunchGraphCompanion']

# How often a launch checks that its nodes' graph still has a daemon (seconds).
DAEMON_CHECK = 1.0
# The daemon starts beside the nodes at a lower CPU priority: on two cores its start-up
# (≈ 0.4 s of CPU) otherwise delayed the nodes' by ≈ 0.3 s (bench/bench_graph.py).
DAEMON_NICE = int(os.environ.get('ROBOT_LAB_DAEMON_NICE', '10'))


class LaunchGraphCompanion:
    """The announcements and graph daemons of one launch; called from its supervisor thread."""

    def __init__(self, *, daemon: bool = False, listener: Listener | None = None,
                 announcement: LaunchAnnouncement | None = None,
                 warn: Callable[[str], None] = lambda message: None) -> None:
        self.daemon = daemon
        self._warn = warn
        # One file per graph the nodes are in; `announcement` is the one the CLI wrote
        # before the launch file was read (it said "starting").
        self._announcements: dict[Path, LaunchAnnouncement] = (
            {} if announcement is None else {announcement.directory: announcement})
        self._daemons: list[subprocess.Popen[bytes]] = []
        self._daemon_of: dict[Path, subprocess.Popen[bytes]] = {}  # the one we started
        self._daemon_graphs: set[Path] = set()
        self._listener = listener
        self._graph_envs: dict[Path, dict[str, str]] = {}  # an environment of each graph

    def graph_of(self, env: Mapping[str, str]) -> Path:
        """The graph a process with this environment joins (remembered for its daemon)."""
        directory = graph_dir(env)
        self._graph_envs.setdefault(directory, dict(env))
        return directory

    def announce(self, nodes: Iterable[tuple[Path, str, int]]) -> None:
        """Tell graph queries which nodes this launch has up or is starting (per graph).

        `nodes` is (graph, full node name, pid); a node not spawned yet is announced with
        the launcher's own pid: it is expected for as long as the launcher lives.
        """
        running: dict[Path, list[tuple[str, int]]] = {d: [] for d in self._announcements}
        for directory, name, pid in nodes:
            running.setdefault(directory, []).append((name, pid))
        for directory, entries in running.items():
            if directory not in self._announcements:
                self._announcements[directory] = LaunchAnnouncement(directory)
            self._announcements[directory].update(entries)

    def start_daemons(self, running: set[Path]) -> None:
        """One daemon per graph this launch's nodes are in, unless one already serves it.

        Started after the nodes (they matter more) from the supervisor's thread, so it dies
        with the launcher like they do.
        """
        if not self.daemon:
            return
        from robot_lab.graph import daemon

        if self._listener is not None:
            listener, self._listener = self._listener, None
            self._daemon_graphs.add(listener.path.parent)
            self._graph_envs.setdefault(listener.path.parent, dict(os.environ))
            try:
                proc = daemon.start(detached=False, listener=listener, nice=DAEMON_NICE)
                self._daemons.append(proc)
                self._daemon_of[listener.path.parent] = proc
            except OSError as exc:
                self._warn(f'no graph daemon: {exc}')
            listener.close(unlink=not self._daemons)  # the daemon has its own copy now
        for directory in running - self._daemon_graphs:
            self._daemon_graphs.add(directory)
            env = self._graph_envs[directory]
            if daemon.is_running(env):
                continue
            try:
                proc = daemon.start(detached=False, env=env, nice=DAEMON_NICE)
                self._daemons.append(proc)
                self._daemon_of[directory] = proc
            except OSError as exc:
                self._warn(f'no graph daemon: {exc}')

    def check_daemons(self, running: set[Path]) -> None:
        """A daemon of another launch serving our graph may end with that launch: then we
        start our own, so the CLI stays fast for as long as our nodes run."""
        from robot_lab.graph import daemon

        self._daemons = [p for p in self._daemons if p.poll() is None]
        for directory in list(self._daemon_graphs):
            ours = self._daemon_of.get(directory)
            if ours is not None and ours.poll() is None:
                continue  # ours is alive (maybe still starting, slow on a loaded machine):
                # starting another now only made it exit at once and linger as a zombie
            if not daemon.is_running(self._graph_envs[directory]):
                self._daemon_graphs.discard(directory)
        self.start_daemons(running)

    def stop_daemons(self) -> None:
        """Ask our daemons to end (at shutdown: they exit while the nodes do)."""
        for proc in self._daemons:
            if proc.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    proc.terminate()

    def close(self) -> None:
        """The launch has ended: withdraw the announcements, reap the daemons."""
        if self._listener is not None:  # never handed to a daemon
            self._listener.close()
        for announcement in self._announcements.values():
            announcement.close()
        self.stop_daemons()
        for proc in self._daemons:
            try:
                proc.wait(2.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
