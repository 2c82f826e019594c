"""`ros2 interface list | head -1`: a reader that goes away ends the command quietly."""

from __future__ import annotations

import fcntl
import os
import subprocess

from conftest import BIN


def test_closed_stdout_ends_without_a_traceback() -> None:
    read_end, write_end = os.pipe()
    # A one-page pipe: the list (~7 KB) cannot fit, so the command is still writing
    # when the reader closes, as with `| head -1` on a long listing.
    fcntl.fcntl(write_end, fcntl.F_SETPIPE_SZ, 4096)
    proc = subprocess.Popen([str(BIN / 'ros2'), 'interface', 'list'],
                            stdout=write_end, stderr=subprocess.PIPE)
    os.close(write_end)
    with os.fdopen(read_end, 'rb') as out:
        assert out.readline() == b'Messages:\n'
    assert proc.stderr is not None
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=30) == 141  # 128 + SIGPIPE, as the shell reports it
    assert err == ''
