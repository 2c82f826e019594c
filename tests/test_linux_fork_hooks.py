"""The fork server's LTTng-UST hooks: found once rcl has loaded the library, then kept
(scanning the process's mappings at every fork took 2.3 ms)."""

from __future__ import annotations

import subprocess
import sys

import pytest

_SCAN = """
from robot_lab.linux import fork, procfs
before = fork.lttng_libraries()
import rclpy._rclpy_pybind11  # rcl: loads LTTng-UST where the wheels bring it
found = fork.lttng_libraries()
procfs.mapped_paths = None  # a scan from now on would raise
print(len(before), len(found), fork.lttng_libraries() is found)
"""


def test_lttng_is_looked_for_until_loaded_then_kept() -> None:
    done = subprocess.run([sys.executable, '-c', _SCAN], capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    before, found, kept = done.stdout.split()
    if found == '0':
        pytest.skip('no LTTng-UST in these wheels: nothing to keep')
    assert (before, kept) == ('0', 'True')
