"""A child's stdout and stderr: read without blocking, printed line by line as launch does.

The supervisor's loop only learns that a pipe is readable or that its child has exited;
turning bytes into lines (a partial line waits for its newline, or for the pipe's end),
printing each with the child's label and reporting it as a process_io event is here.
"""

from __future__ import annotations

import os
import selectors
import subprocess

from robot_lab.launch.event_router import EventRouter
from robot_lab.launch.fork_client import ForkedProcess
from robot_lab.launch.output import LaunchOutput
from robot_lab.launch.process_record import ProcessRecord

__all__ = ['ChildOutput']


class ChildOutput:
    """The pipes of every child of one launch, registered in its loop's selector."""

    def __init__(self, selector: selectors.BaseSelector, output: LaunchOutput,
                 events: EventRouter) -> None:
        self._selector = selector
        self._output = output
        self._events = events

    def watch(self, record: ProcessRecord, popen: subprocess.Popen[bytes] | ForkedProcess) -> None:
        """A child just started: its pipes are read from now on, keyed ('pipe', record, stream)."""
        record.partial = {'stdout': b'', 'stderr': b''}
        record.open_streams = 0
        for stream, pipe in (('stdout', popen.stdout), ('stderr', popen.stderr)):
            if pipe is None:
                continue
            os.set_blocking(pipe.fileno(), False)
            self._selector.register(pipe.fileno(), selectors.EVENT_READ, ('pipe', record, stream))
            record.open_streams += 1

    def read(self, record: ProcessRecord, stream: str, fd: int) -> None:
        try:
            data = os.read(fd, 65536)
        except BlockingIOError:
            return
        except OSError:
            data = b''
        if not data:
            self._close_stream(record, stream, fd)
            return
        self._emit_lines(record, stream, record.partial.get(stream, b'') + data)

    def drain(self, record: ProcessRecord) -> None:
        """Read what the exited child left in its pipes, then close them."""
        popen = record.popen
        assert popen is not None
        for stream, pipe in (('stdout', popen.stdout), ('stderr', popen.stderr)):
            if pipe is None:
                continue
            fd = pipe.fileno()
            while True:
                try:
                    data = os.read(fd, 65536)
                except (BlockingIOError, OSError):
                    break  # a grandchild may hold the pipe open; do not wait for it
                if not data:
                    break
                self._emit_lines(record, stream, record.partial.get(stream, b'') + data)
            self._close_stream(record, stream, fd)
            pipe.close()

    def _emit_lines(self, record: ProcessRecord, stream: str, buffer: bytes) -> None:
        *complete, rest = buffer.split(b'\n')
        for raw in complete:
            self._output.child(record.label, stream, record.spec.output,
                               raw.rstrip(b'\r').decode('utf-8', errors='replace'))
            if record.pid is not None and self._events.wants('process_io'):
                self._events.output(record.spec, record.pid, stream, raw.rstrip(b'\r'))
        record.partial[stream] = rest

    def _close_stream(self, record: ProcessRecord, stream: str, fd: int) -> None:
        try:
            self._selector.unregister(fd)
        except (KeyError, ValueError):
            return
        rest = record.partial.get(stream, b'')
        if rest:
            self._output.child(record.label, stream, record.spec.output,
                               rest.decode('utf-8', errors='replace'))
            record.partial[stream] = b''
        record.open_streams -= 1
