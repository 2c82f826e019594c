"""The cgroups a root grader puts each job in: its tasks and its memory, bounded as a whole.

Rlimits bound each process, not the job: the kernel does not hold root to RLIMIT_NPROC, and
a submission may fork 250 processes of 1.4 GB each (within `processes` and `memory_mb`) and
take the grading host's RAM. So a root grader makes, per job, a pids group (`pids.max`:
the rubric's `processes`) and a memory group (the rubric's `job_memory_mb` for every
process of the job together; swap not on top of it); the job writes itself into them
first thing (sandbox.enter), every child inherits them, and past the limit the kernel's
OOM killer stops a process of the job, never one of the host. The grader reads afterwards
whether that happened, for the student's feedback, and removes the groups.

cgroup v1 keeps pids and memory in separate hierarchies: a group in each, made inside the
grader's own group (so whatever bounds the grader, a container or a slice, bounds its
jobs too). cgroup v2 has one group with both, at the root (a v2 group that holds
processes cannot hand controllers to its children). Where no group can be made (a grader
that is not root, no controller, a read-only /sys), there is none and nothing is said:
the rlimits alone bound the job, as before.
"""

from __future__ import annotations

import contextlib
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.grading.package.rubric import Limits
from robot_lab.linux import procfs

__all__ = ['JobCgroups', 'job_cgroups', 'memory_cgroup_possible']

_ROOT = Path('/sys/fs/cgroup')
_PREFIX = 'robot_lab-'
MB = 1024 * 1024


@dataclass
class JobCgroups:
    """The groups a job enters (`paths`), and the one that bounds its memory (None: none
    could be made; the rlimits alone bound it)."""

    paths: list[Path] = field(default_factory=list)
    memory: Path | None = None

    def out_of_memory(self) -> bool:
        """Did the job reach its memory limit and the kernel stop one of its processes (or
        refuse it memory)?"""
        if self.memory is None:
            return False
        if (self.memory / 'memory.events').is_file():  # v2
            events = _counters(self.memory / 'memory.events')
            return events.get('oom_kill', 0) > 0 or events.get('oom', 0) > 0
        control = _counters(self.memory / 'memory.oom_control')
        if 'oom_kill' in control:  # v1, Linux 4.13+
            return control['oom_kill'] > 0 or control.get('under_oom', 0) > 0
        # Older v1: failcnt also counts page cache reclaimed at the limit, but an honest
        # job stays far below it.
        return _number(self.memory / 'memory.failcnt') > 0

    def peak_mb(self) -> float | None:
        """The most memory the whole job held at once (page cache included), in MB."""
        if self.memory is None:
            return None
        for name in ('memory.max_usage_in_bytes', 'memory.peak'):  # v1, v2 (Linux 5.19+)
            if (self.memory / name).is_file():
                return _number(self.memory / name) / MB
        return None

    def remove(self) -> None:
        """rmdir each group once its last task has gone (a killed task takes a moment)."""
        for group in self.paths:
            _remove_cgroup(group)


def _number(path: Path) -> int:
    try:
        return int(path.read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return 0


def _counters(path: Path) -> dict[str, int]:
    """`name value` lines (memory.events, memory.oom_control)."""
    found = {}
    with contextlib.suppress(OSError):
        for line in path.read_text().splitlines():
            name, _, value = line.partition(' ')
            with contextlib.suppress(ValueError):
                found[name] = int(value)
    return found


def _own_v1_group(controller: str) -> Path:
    """Where a v1 hierarchy of `controller` keeps this process: a job's group goes inside
    it. The hierarchy's root when that folder is not visible (a container's own view)."""
    base = _ROOT / controller
    where = procfs.cgroups().get(controller)
    if where is None:
        return base
    inside = base / where.lstrip('/')
    return inside if inside.is_dir() else base


def _v2_controllers() -> set[str]:
    """The controllers a v2 root hands to its children (none on a v1 or hybrid host)."""
    if not (_ROOT / 'cgroup.subtree_control').is_file():
        return set()
    try:
        return set((_ROOT / 'cgroup.subtree_control').read_text().split())
    except OSError:
        return set()


def _make(parent: Path, name: str, settings: list[tuple[str, str, bool]]) -> Path | None:
    """A new group under `parent` with each (file, value, required) written; None if it
    cannot be made or a required setting is refused."""
    if not (parent / 'cgroup.procs').is_file():
        return None
    _remove_stale_cgroups(parent)
    group = parent / f'{_PREFIX}{name}'
    try:
        group.mkdir()
    except OSError:
        return None
    for file, value, required in settings:
        if not (group / file).exists() and not required:
            continue
        try:
            (group / file).write_text(value)
        except OSError:
            if required:
                _remove_cgroup(group)
                return None
    return group


def job_cgroups(name: str, limits: Limits) -> JobCgroups:
    """The groups of job `name`: tasks capped at `limits.processes`, memory at
    `limits.job_memory_mb` (with no swap beyond it), when this process is root and may make
    them; else none."""
    made = JobCgroups()
    if os.geteuid() != 0:
        return made
    memory = str(limits.job_memory_mb * MB)
    v2 = _v2_controllers()
    if v2 & {'pids', 'memory'}:
        settings = []
        if 'pids' in v2:
            settings.append(('pids.max', str(limits.processes), True))
        if 'memory' in v2:
            settings += [('memory.max', memory, True), ('memory.swap.max', '0', False)]
        group = _make(_ROOT, name, settings)
        if group is not None:
            made.paths.append(group)
            made.memory = group if 'memory' in v2 else None
        return made
    pids = _make(_own_v1_group('pids'), name, [('pids.max', str(limits.processes), True)])
    if pids is not None:
        made.paths.append(pids)
    # memsw (memory + swap) only after memory: it may never be below it.
    group = _make(_own_v1_group('memory'), name, [
        ('memory.limit_in_bytes', memory, True),
        ('memory.memsw.limit_in_bytes', memory, False)])
    if group is not None:
        made.paths.append(group)
        made.memory = group
    return made


def memory_cgroup_possible() -> bool:
    """Can this grader bound a job's memory as a whole (for the containment line)? Tried
    by making a group and removing it."""
    probe = job_cgroups(f'probe-{os.getpid()}', Limits())
    probe.remove()
    return probe.memory is not None


def _remove_stale_cgroups(parent: Path) -> None:
    """Remove the empty job groups of graders that were killed (-9) before cleaning up; a
    group made in the last minute may belong to a job about to enter it."""
    for group in parent.glob(f'{_PREFIX}*'):
        with contextlib.suppress(OSError):
            if time.time() - group.stat().st_mtime > 60:
                group.rmdir()  # fails while tasks are in it


def _remove_cgroup(group: Path) -> None:
    deadline = time.monotonic() + 5.0
    while True:
        try:
            group.rmdir()
            return
        except FileNotFoundError:
            return
        except OSError:
            if time.monotonic() > deadline:
                return
            time.sleep(0.05)
