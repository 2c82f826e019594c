"""The `parent_death` capability on and off, seen from the child: `spawn()`'s children ask
the kernel for SIGKILL when their parent dies, and none do with it switched off (the
launch test in test_linux.py runs a whole launch that way; this says the switch took)."""

from __future__ import annotations

import signal
import sys

import pytest

from robot_lab.linux import capabilities
from robot_lab.process import spawn

# prctl(PR_GET_PDEATHSIG = 2): the signal this process gets when its parent dies (0: none)
_ASK = """
import ctypes
sig = ctypes.c_int(-1)
assert ctypes.CDLL(None, use_errno=True).prctl(2, ctypes.byref(sig), 0, 0, 0) == 0
print(sig.value)
"""


def _parent_death_signal() -> int:
    child = spawn([sys.executable, '-c', _ASK])
    out, _ = child.communicate(timeout=60)
    assert child.returncode == 0, out
    return int(out)


def test_a_spawned_child_dies_with_its_parent_unless_switched_off() -> None:
    if not capabilities.available('parent_death'):
        pytest.skip(f'no parent-death signal here: {capabilities.reason("parent_death")}')
    assert _parent_death_signal() == signal.SIGKILL
    with capabilities.switched_off('parent_death'):
        assert _parent_death_signal() == 0


def test_the_variable_switches_it_off_as_the_block_does(monkeypatch: pytest.MonkeyPatch) -> None:
    """A launcher started with ROBOT_LAB_DISABLE=parent_death (as the capability-off launch
    test starts one) spawns its nodes without it."""
    monkeypatch.setenv(capabilities.DISABLE_VARIABLE, 'parent_death')
    assert _parent_death_signal() == 0
