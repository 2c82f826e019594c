"""What this machine offers the kit, what the kit does without each, and the switch that
makes it do without.

Each capability has a probe (None: works here; else why not) and a fallback the kit takes
when the probe fails or the capability is switched off: by `ROBOT_LAB_DISABLE=NAME,...`
in the environment (so every process of a launch agrees, the fork server and the nodes
included) or by `switched_off(NAME)` in this process (tests). A probe runs once per
process, under a lock, the first time its capability is asked about.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import threading
from collections.abc import Callable, Iterator, Mapping
from typing import NamedTuple

__all__ = [
    'CAPABILITIES',
    'DISABLE_VARIABLE',
    'Capability',
    'Row',
    'available',
    'child_environment',
    'disabled',
    'reason',
    'switched_off',
    'table',
]

DISABLE_VARIABLE = 'ROBOT_LAB_DISABLE'


class Capability(NamedTuple):
    name: str
    what: str  # what it is, in a few words
    fallback: str  # what the kit does without it
    probe: str  # 'module:function' in this package, returning None or why it is missing


CAPABILITIES: dict[str, Capability] = {c.name: c for c in (
    Capability('fork_server', 'launch forks Python nodes from a warm server',
               'execs each Python node (slower start, more memory)', 'fork:probe'),
    Capability('sock_diag', 'netlink sock_diag reads the host UDP socket table',
               'reads /proc/net/udp (can miss a socket while others come and go)',
               'sock_diag:probe'),
    Capability('pidfd', 'pidfd_open: waits and signals without a pid race',
               "polls each exec'd node with waitpid every 100 ms", 'pidfd:probe'),
    Capability('namespaces', 'unshare: user, mount, PID, network and IPC namespaces',
               'refuses to grade, saying why and how (--no-sandbox: no containment)',
               'namespaces:probe'),
    Capability('parent_death', 'prctl(PR_SET_PDEATHSIG): children die with their parent',
               'stops children only while it lives (kill -9 leaves them running)',
               'prctl:probe'),
)}

_lock = threading.Lock()
_probed: dict[str, str | None] = {}
_off: dict[str, int] = {}  # switched off in this process (nesting count)


def _named(names: str) -> set[str]:
    return {n.strip() for n in names.split(',') if n.strip()}


def disabled(name: str, environ: Mapping[str, str] | None = None) -> bool:
    """Whether `name` is switched off (ROBOT_LAB_DISABLE or `switched_off`)."""
    if name not in CAPABILITIES:
        raise KeyError(f'no capability {name!r}: one of {", ".join(CAPABILITIES)}')
    env = os.environ if environ is None else environ
    return name in _named(env.get(DISABLE_VARIABLE, '')) or _off.get(name, 0) > 0


def reason(name: str) -> str | None:
    """Why `name` is missing here (None: it works); switched off counts as missing."""
    if disabled(name):
        return f'switched off ({DISABLE_VARIABLE} or switched_off)'
    with _lock:
        if name not in _probed:
            module, function = CAPABILITIES[name].probe.split(':')
            probe: Callable[[], str | None] = getattr(
                importlib.import_module(f'robot_lab.linux.{module}'), function)
            try:
                _probed[name] = probe()
            except Exception as exc:  # a probe that fails says so, never the kit
                _probed[name] = f'{type(exc).__name__}: {exc}'
        return _probed[name]


def available(name: str) -> bool:
    """Whether the kit may use `name` in this process (not switched off, probe passed)."""
    return reason(name) is None


@contextlib.contextmanager
def switched_off(*names: str) -> Iterator[None]:
    """Do without these capabilities in this process while the block runs (children
    started meanwhile get them in ROBOT_LAB_DISABLE too, see `child_environment`)."""
    for name in names:
        if name not in CAPABILITIES:
            raise KeyError(f'no capability {name!r}')
    with _lock:
        for name in names:
            _off[name] = _off.get(name, 0) + 1
    try:
        yield
    finally:
        with _lock:
            for name in names:
                _off[name] -= 1


def child_environment(env: Mapping[str, str]) -> dict[str, str]:
    """`env` with this process's switched-off capabilities added to ROBOT_LAB_DISABLE."""
    off = {n for n, count in _off.items() if count > 0} | _named(env.get(DISABLE_VARIABLE, ''))
    result = dict(env)
    if off:
        result[DISABLE_VARIABLE] = ','.join(sorted(off))
    return result


class Row(NamedTuple):
    name: str
    available: bool
    why_not: str | None
    what: str
    fallback: str


def table() -> list[Row]:
    """One row per capability, for the doctor."""
    rows = []
    for cap in CAPABILITIES.values():
        why = reason(cap.name)
        rows.append(Row(cap.name, why is None, why, cap.what, cap.fallback))
    return rows
