"""The launch's nodes as graph queries see them: announced, served by a daemon, still hearing.

The supervisor knows processes and their states; what that means for the ROS graph (which
nodes to announce as up or expected, which graphs need a graph daemon, which node has gone
deaf to new participants) is worked out here from its records, and handed to
graph.launch_companion or printed as a warning.
"""

from __future__ import annotations

import os
from pathlib import Path

from robot_lab.graph.launch_companion import LaunchGraphCompanion
from robot_lab.launch.output import LaunchOutput
from robot_lab.launch.process_record import ProcessRecord
from robot_lab.shared_memory import lost_ports

__all__ = ['GraphWatch']


class GraphWatch:
    """Reads the supervisor's records (the same list, kept current by it); its thread only."""

    def __init__(self, records: list[ProcessRecord], graph: LaunchGraphCompanion,
                 output: LaunchOutput) -> None:
        self._records = records
        self._graph = graph
        self._output = output
        self._deaf: set[int] = set()  # pids said to no longer hear (check_hearing)

    def announce(self, *, shutting_down: bool) -> None:
        """The nodes this launch has up (their pid) or is about to start (the launcher's)."""
        nodes: list[tuple[Path, str, int]] = []
        for record in self._records:
            if record.graph is None or not record.spec.node_name:
                continue
            if record.state == 'running' and record.pid:
                nodes.append((record.graph, record.spec.node_name, record.pid))
            elif record.state == 'pending' and not shutting_down:
                nodes.append((record.graph, record.spec.node_name, os.getpid()))
        self._graph.announce(nodes)

    def _running_graphs(self) -> set[Path]:
        return {r.graph for r in self._records if r.graph is not None and r.state == 'running'}

    def start_daemons(self) -> None:
        self._graph.start_daemons(self._running_graphs())

    def check_daemons(self) -> None:
        self._graph.check_daemons(self._running_graphs())

    def check_hearing(self) -> None:
        """Say once of each node that no longer hears new participants (Fast DDS took over
        its shared-memory port on a crowded host, robot_lab.shared_memory.lost_ports): a
        `topic echo` started later would wait for its messages forever."""
        for record in self._records:
            if record.state != 'running' or not record.pid or record.pid in self._deaf:
                continue
            if ports := lost_ports(record.pid):
                self._deaf.add(record.pid)
                self._output.launcher(
                    'WARNING', record.label,
                    f'no longer hears ROS participants started from now on: Fast DDS took '
                    f'over its shared-memory port {", ".join(map(str, ports))} (a crowded '
                    f'host); stop the launch (Ctrl-C) and start it again')
