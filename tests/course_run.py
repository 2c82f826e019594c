"""Run the course notebooks in real kernels (nbclient), the way a student runs them.

Shared by the mistake-path tests: a course workspace and ROS domain for the run, one kernel
per notebook, the cells a student's copy starts from, and a probe of what a kernel still
runs at the end (its child processes, the nodes spinning in it).
"""

from __future__ import annotations

import copy
import json
import os
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import nbformat
from jupyter_client.manager import AsyncKernelManager
from nbclient import NotebookClient
from nbformat import NotebookNode

from robot_lab.graph import daemon
from robot_lab.graph.daemon import AUTOSTART_VARIABLE as AUTOSTART

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = REPO / 'notebooks'
COURSE = ['00_welcome', '01_create_package', '02_write_nodes', '03_launch_files',
          '04_parameters', '05_inspect_and_verify', '06_ros_bags', '07_capstone',
          '08_debugging']

# A cell that takes longer than this hangs (no cell of the course needs a minute).
CELL_TIMEOUT = 90

# What the kernel still runs after the notebook's last cell. The lesson's graph daemon is
# not counted: it serves the notebook's commands and ends with the kernel (_no_daemon_left);
# nor is robot_lab.tf_buffer()'s hidden listener, the session's own buffer, kept for its life.
PROBE = """
import json as _j, psutil as _p
from robot_lab import rclpy_session as _c
_kids = [' '.join(k.cmdline()[:4]) for k in _p.Process().children(recursive=True)
         if k.is_running() and k.status() != _p.STATUS_ZOMBIE
         and '--robot-lab-graph-daemon' not in k.cmdline()]
_nodes = [n.get_name() for s in _c._SESSIONS.values() if s._nodes_executor is not None
          for n in s._nodes_executor.get_nodes() if not n.get_name().startswith('_robot_lab_tf_')]
print('PROBE ' + _j.dumps({'children': _kids, 'nodes': _nodes}))
"""


def source(name: str) -> NotebookNode:
    return nbformat.read(NOTEBOOKS / f'{name}.ipynb', as_version=4)


def student_cells(name: str) -> dict[str, NotebookNode]:
    """The student's copy of each cell (answers replaced by nbgrader's placeholder), by id."""
    from robot_lab.grading.exercises import student_notebook

    return {c.get('id', ''): c for c in student_notebook(NOTEBOOKS / f'{name}.ipynb').cells}


def text(cell: NotebookNode) -> str:
    """What a cell showed: its streams and its error (as IPython rendered it)."""
    out = []
    for o in cell.get('outputs', []):
        if o.output_type == 'stream':
            out.append(o.text)
        elif o.output_type == 'error':
            out.append('\n'.join(o.traceback))
    return ''.join(out)


def error(cell: NotebookNode) -> NotebookNode | None:
    return next((o for o in cell.get('outputs', []) if o.output_type == 'error'), None)


def fresh(cell: NotebookNode, source_text: str | None = None) -> NotebookNode:
    """A copy of `cell` to run again (optionally with other source)."""
    made = copy.deepcopy(cell)
    if made.cell_type == 'code':
        made.outputs, made.execution_count = [], None
    if source_text is not None:
        made.source = source_text
    return made


@dataclass
class Course:
    """One run's workspace and domain; each notebook gets a kernel of its own."""

    workspace: Path
    domain: int

    @contextmanager
    def environment(self, name: str) -> Iterator[None]:
        number = int(name[:2])
        saved = {k: os.environ.get(k) for k in
                 ('ROBOT_LAB_WORKSPACE', 'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE', 'ROBOT_LAB_HEADLESS',
                  AUTOSTART)}
        os.environ.update({'ROBOT_LAB_WORKSPACE': str(self.workspace),
                           # a student's graph verbs warm up a daemon; it ends with the
                           # kernel (each kernel is a session of its own): nothing outlives
                           # the run. Cold, the course took 147 s here; warm, 136 s.
                           AUTOSTART: '1',
                           # setup() picks base + lesson number: this run's domain for all
                           'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE': str(self.domain - number),
                           'ROBOT_LAB_HEADLESS': '1'})
        try:
            yield
        finally:
            for key, value in saved.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value

    def run(self, name: str, cells: Sequence[NotebookNode],
            on_cell: Callable[[int, NotebookNode], None] | None = None) -> dict[str, Any]:
        """Execute `cells` in one new kernel (errors do not stop it); what is left running.

        A cell that hangs fails the run (nbclient's CellTimeoutError names it).
        """
        made = [fresh(c) for c in cells]
        for n, cell in enumerate(made):  # copies of a cell need ids of their own, before
            cell.id = f'{n}-{cell.get("id", "")}'[:64]  # nbformat validates (and warns)
        nb = nbformat.v4.new_notebook(cells=made, metadata=source(name).metadata)
        nb.cells.append(nbformat.v4.new_code_cell(PROBE))
        self.workspace.mkdir(parents=True, exist_ok=True)
        # Unix sockets, not TCP ports another worker's kernel may take first (the grader's)
        connection = self.workspace.parent / f'{name}-{uuid.uuid4().hex[:8]}.json'
        km = AsyncKernelManager(kernel_name='robot_lab', transport='ipc',
                                connection_file=str(connection))
        client = NotebookClient(nb, km=km, timeout=CELL_TIMEOUT, allow_errors=True,
                                interrupt_on_timeout=False, kernel_name='robot_lab',
                                resources={'metadata': {'path': str(self.workspace)}})
        # cleanup_kc: nbclient shuts down only kernels whose manager it made. Left alive,
        # a run's kernel outlived its module, and with it its ROS session, in a domain the
        # next module was given (a later module's `topic list` showed 07's /distance).
        with self.environment(name), client.setup_kernel(cleanup_kc=True):
            for index, cell in enumerate(nb.cells):
                client.execute_cell(cell, index)
                if on_cell is not None and index < len(nb.cells) - 1:
                    on_cell(index, cell)
        self.cells = nb.cells
        self._no_daemon_left()
        last = text(nb.cells[-1])
        found: dict[str, Any] = json.loads(last.split('PROBE ', 1)[1])
        return found

    def _no_daemon_left(self) -> None:
        """The graph daemon a command in the kernel started ends with the kernel: it sees
        its owner gone within half a second, at a low priority (a busy host delays it); one
        that did not would run for its idle timeout, two hours."""
        graph = {**os.environ, 'ROS_DOMAIN_ID': str(self.domain)}
        deadline = time.monotonic() + 30
        while daemon.is_running(graph):
            assert time.monotonic() < deadline, \
                f'the graph daemon of domain {self.domain} outlived its kernel by 30 s'
            time.sleep(0.1)
