"""One submission's job, fenced in: its own ROS domain, HOME, TMPDIR, limits and namespaces.

The grader starts each job as `python -m robot_lab.grading.package.job JOBDIR` through
`robot_lab.process.spawn` (parent-death signal), wrapped in util-linux `unshare` with new
mount, PID (and its own /proc), network and IPC namespaces — plus a user namespace when
the grader is not root: the job sees only a loopback interface (no DDS traffic leaves it or
reaches another job, no host service is reachable), no host process, and is PID 1 of its
namespace, so when it dies — stopped at its time budget, or because the grader was killed
with `kill -9` — the kernel kills every process the submission started, forked daemons
included. `confinement` then gives it a read-only machine with only its own folder and a
private /tmp writable, and takes its privileges (uid 200000+domain, named `student` in the
job's own /etc/passwd, with HOME, USER, LOGNAME and a UTF-8 locale set; no capabilities).
Where no namespace can be made the grader refuses, root or not, unless told `--no-sandbox`
(`check_can_contain`, robot_lab.grading.package.containment); then the job leads its own
process group, which the grader kills, and every process carries a token in its
environment that a final sweep looks for.

Inside, `enter()` applies the resource limits (CPU seconds, memory, file size, process
count) that every child inherits. Those bound each process, not the job, and the kernel
does not hold root to RLIMIT_NPROC: so a grader running as root also puts each job in
cgroups of its own (robot_lab.grading.package.cgroups) that bound its processes and
threads, and the memory of all of them together; a job the kernel stopped at that limit
says so in its JobRun (`out_of_memory`), for the student's feedback.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import resource
import shutil
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from robot_lab.grading.package.cgroups import job_cgroups
from robot_lab.grading.package.containment import (
    NO_SANDBOX_VAR,
    containment_line,
    namespaces_available,
    refusal,
    unshare_args,
)
from robot_lab.grading.package.rubric import Limits
from robot_lab.process import spawn

__all__ = ['BLOCKED', 'GRADER_PROBLEM', 'NOT_SET_UP', 'JobRun', 'check_can_contain', 'enter',
           'job_domains', 'namespaces_available', 'run_job', 'stop_jobs', 'sweep']

TOKEN_VAR = 'ROBOT_LAB_GRADE_JOB'
CGROUP_VAR = 'ROBOT_LAB_GRADE_CGROUP'  # the job's cgroups, os.pathsep between them
UID_VAR = 'ROBOT_LAB_GRADE_UID'
REPORT_FD_VAR = 'ROBOT_LAB_GRADE_REPORT_FD'  # the pipe a job sends its report through
# A folder that keeps each job's log (STUDENT.log: steps, waits, the nodes' output) after
# its job folder is removed: to see why a grade came out as it did.
JOB_LOGS_VAR = 'ROBOT_LAB_GRADE_JOB_LOGS'
# The job's locale: the same for every student whatever the instructor's terminal says
# (C.UTF-8 is built into glibc since 2.35 and patched into Debian's for longer).
_LOCALE = {'LANG': 'C.UTF-8'}
# What the sandbox stopped in this job (signals sent to it from inside), for the feedback.
BLOCKED: list[str] = []


@contextlib.contextmanager
def job_domains(jobs: int) -> Iterator[list[int]]:
    """The ROS domain of each parallel job slot, for as long as the grading runs.

    ROS_DOMAIN_ID set by hand (or by a test): that domain and the next `jobs - 1`, as
    `robot-lab grade` of notebooks does. Otherwise domains leased from the host registry
    (robot_lab.domain), so no user and no other grading run is in them.
    """
    from robot_lab.domain import lease_domains, resolve

    choice = resolve()
    if choice.source == 'variable':
        yield [(choice.domain + k) % 233 for k in range(jobs)]
        return
    with lease_domains(jobs, purpose='robot-lab grade') as leased:
        yield leased


def check_can_contain(no_sandbox: bool = False, limits: Limits | None = None) -> str:
    """Refuse to run students' code with nothing around it, root or not (unless
    `no_sandbox`: RobotLabError saying why and how to allow namespaces); else the one line
    that says how each job will be contained (`limits`: the rubric's)."""
    from robot_lab.errors import RobotLabError

    if no_sandbox or os.environ.get(NO_SANDBOX_VAR):
        os.environ[NO_SANDBOX_VAR] = '1'  # for the jobs run_job starts
        return containment_line(limits or Limits(), no_sandbox=True)
    refused = refusal()
    if refused is not None:
        raise RobotLabError(refused[0], fix=refused[1])
    return containment_line(limits or Limits(), no_sandbox=False)


def _loopback_up() -> None:
    """A fresh network namespace has `lo` down; DDS on localhost needs it up."""
    siocgifflags, siocsifflags, iff_up = 0x8913, 0x8914, 0x1
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        request = struct.pack('16sh', b'lo', 0)
        flags = struct.unpack('16sh', fcntl.ioctl(sock, siocgifflags, request))[1]
        if not flags & iff_up:
            fcntl.ioctl(sock, siocsifflags, struct.pack('16sh', b'lo', flags | iff_up))


def _init_process() -> None:
    """As PID 1 of the namespace: fork the real job, reap orphans, exit with the job.

    The job must not be PID 1 itself: robot_lab.process.spawn's children take a parent
    with PID 1 for a dead one and exit at once. When this process exits, the kernel
    kills everything left in the namespace.
    """
    child = os.fork()
    if child == 0:
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    while True:
        try:
            pid, status = os.wait()
        except ChildProcessError:
            os._exit(1)
        if pid == child:  # a shell's convention: 128 + N for a job killed by signal N
            code = os.waitstatus_to_exitcode(status)
            os._exit(128 - code if code < 0 else code & 0xFF)


# A job's address space may be this many times its memory (`enter`): threads and glibc's
# malloc arenas reserve far more than they use.
ADDRESS_SPACE_FACTOR = 4
# What `enter` could not set up in the job's view of the machine: notes of the job's report.
GRADER_PROBLEM = 'the grader could not set up'
NOT_SET_UP: list[str] = []


def _record_signal(signum: int, _frame: object) -> None:
    name = signal.Signals(signum).name
    if not any(name in b for b in BLOCKED):
        BLOCKED.append(f'a process of the submission sent {name} to the grading job; the '
                       'sandbox ignored it')


def enter(limits: Limits, in_namespace: bool, job_dir: Path | None = None) -> None:
    """Run first thing in the job: its cgroups, loopback up, the job's view of the machine
    and an unprivileged identity (`confinement`), own process group, limits."""
    for group in filter(None, os.environ.get(CGROUP_VAR, '').split(os.pathsep)):
        with contextlib.suppress(OSError):  # '0': this process, whatever its PID namespace
            Path(group, 'cgroup.procs').write_text('0')
    # A process group of its own, in a namespace too: else the job, its launcher and the
    # student's nodes share the group of whatever started the grader, and a SIGINT meant
    # for that group (Jupyter interrupting the kernel that runs `robot-lab grade` sends
    # it with killpg, a terminal's Ctrl-C, a shell's `kill -INT` of a job) stops a
    # student's nodes before they are observed (issue 22: a sensor that died of rclpy's
    # ExternalShutdownException mid-grading).
    with contextlib.suppress(OSError):
        os.setpgrp()
    if in_namespace:
        from robot_lab.grading.package.confinement import confine, drop_privileges

        _loopback_up()
        uid = int(os.environ[UID_VAR]) if os.environ.get(UID_VAR) else None
        home = os.environ.get('HOME')
        for problem in confine(job_dir or Path.cwd(), uid, Path(home) if home else None):
            # The grader's own fault, never the student's: said in the job's log and in its
            # report, so a job whose nodes then miss their passwd entry shows why (seen once,
            # under load) to the instructor and in the feedback.
            print(f'[grader] sandbox: could not set up {problem}', file=sys.stderr, flush=True)
            NOT_SET_UP.append(f'{GRADER_PROBLEM} {problem} (not your fault: code that needs '
                              'it may have failed)')
        drop_privileges(uid)
        if os.getpid() == 1:
            _init_process()
        for signum in (signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1,
                       signal.SIGUSR2):
            signal.signal(signum, _record_signal)
    mb = 1024 * 1024
    wanted = {
        resource.RLIMIT_CPU: limits.cpu_seconds,
        # Memory is what a process holds: heap, anonymous maps, thread stacks (Linux 4.7+
        # counts every private writable mapping). Address space would count what glibc only
        # reserves: an rclpy node reserves 720 MB, and a MultiThreadedExecutor() on a
        # 32-core grading server (32 threads) passed 1.5 GB and could not start a thread.
        resource.RLIMIT_DATA: limits.memory_mb * mb,
        # A backstop for shared mappings, which RLIMIT_DATA does not count.
        resource.RLIMIT_AS: limits.memory_mb * mb * ADDRESS_SPACE_FACTOR,
        resource.RLIMIT_FSIZE: limits.file_mb * mb,
        resource.RLIMIT_NPROC: limits.processes,
        resource.RLIMIT_CORE: 0,
    }
    for which, value in wanted.items():
        _soft, hard = resource.getrlimit(which)
        if hard != resource.RLIM_INFINITY:
            value = min(value, hard)
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(which, (value, value))
    # A write past RLIMIT_FSIZE fails with EFBIG instead of killing the writer.
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


@dataclass
class JobRun:
    """How a job's process ended: exit code (None if killed at its budget), output tail."""

    returncode: int | None
    timed_out: bool
    output: str
    elapsed: float
    isolated: bool  # ran in its own namespaces
    # The job as a whole reached the rubric's job_memory_mb and the kernel stopped a process
    # of it; and the most it held at once (None: no memory cgroup, only per-process limits).
    out_of_memory: bool = False
    memory_peak_mb: float | None = None


def _tail(path: Path, limit: int) -> str:
    try:
        with path.open('rb') as f:
            f.seek(0, os.SEEK_END)
            size = f.tell()
            f.seek(max(0, size - limit))
            text = f.read().decode(errors='replace')
    except OSError:
        return ''
    return ('[... earlier output cut ...]\n' if size > limit else '') + text


def run_job(job_dir: Path, domain: int, limits: Limits, token: str,
            argv: Sequence[str] = ('-m', 'robot_lab.grading.package.job')) -> JobRun:
    """Run the job in `job_dir` (its job.json is already written) and wait at most
    `limits.wall_seconds`; every process of the job is gone when this returns.

    `argv`: the Python arguments of the job (JOBDIR is appended).
    """
    home, tmp = job_dir / 'home', job_dir / 'tmp'
    home.mkdir(exist_ok=True)
    tmp.mkdir(exist_ok=True)
    # matplotlib (the graph picture) would rebuild its font list in every private HOME.
    fonts = Path.home() / '.cache' / 'matplotlib'
    for cached in fonts.glob('fontlist-*.json') if fonts.is_dir() else []:
        (home / '.cache' / 'matplotlib').mkdir(parents=True, exist_ok=True)
        with contextlib.suppress(OSError):
            shutil.copyfile(cached, home / '.cache' / 'matplotlib' / cached.name)
    isolated = namespaces_available() and not os.environ.get(NO_SANDBOX_VAR)
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(('JPY_', 'JUPYTER', 'ROBOT_LAB_GRAPH_DAEMON'))}
    env.update({
        'HOME': str(home), 'TMPDIR': str(tmp), 'ROS_DOMAIN_ID': str(domain),
        'ROS_LOG_DIR': str(job_dir / 'ros_log'), 'ROBOT_LAB_WORKSPACE': str(job_dir / 'ws'),
        'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST', 'PYTHONDONTWRITEBYTECODE': '1',
        'ROBOT_LAB_GRADE_ISOLATED': '1' if isolated else '', TOKEN_VAR: token,
        'PYTHONUNBUFFERED': '1', 'ROBOT_LAB_NO_DAEMON': '1',
        # glibc reserves 64 MB of address space per malloc arena, up to 8 per core: on a
        # many-core server a threaded node would reach the address-space backstop.
        'MALLOC_ARENA_MAX': '4',
    })
    env.pop('ROS_STATIC_PEERS', None)
    for name in [k for k in env if k.startswith('LC_') or k == 'LANGUAGE']:
        del env[name]
    env.update(_LOCALE)
    groups = job_cgroups(token, limits)
    if groups.paths:
        env[CGROUP_VAR] = os.pathsep.join(str(g) for g in groups.paths)
    cmd = [sys.executable, *argv, str(job_dir)]
    if isolated:
        from robot_lab.grading.package.confinement import JOB_USER, job_uid
        from robot_lab.linux.namespaces import in_initial_user_namespace

        cmd = [shutil.which('unshare') or 'unshare', *unshare_args(), *cmd]
        env.update({UID_VAR: str(job_uid(domain)), 'USER': JOB_USER, 'LOGNAME': JOB_USER})
        if os.geteuid() == 0 and in_initial_user_namespace():  # the job setresuid()s
            _chown_tree(job_dir, job_uid(domain))
    log = job_dir / 'job.log'
    started = time.monotonic()
    # The report comes back through a pipe, not a file in the folder the student's code
    # may write: the job's last complete report wins (robot_lab.grading.package.job).
    read_end, write_end = os.pipe()
    env[REPORT_FD_VAR] = str(write_end)
    reports: list[bytes] = []
    reader = threading.Thread(target=_read_reports, args=(read_end, reports), daemon=True)
    reader.start()
    with log.open('wb') as out:
        try:
            proc = spawn(cmd, env=env, cwd=job_dir, stdout=out, stderr=subprocess.STDOUT,
                         pass_fds=(write_end,))
        finally:
            os.close(write_end)
        with _RUNNING_LOCK:
            _RUNNING.add(proc)
            if _STOPPING.is_set():
                proc.kill()
        timed_out = False
        try:
            proc.wait(limits.wall_seconds)
        except subprocess.TimeoutExpired:
            timed_out = True
        finally:
            _kill(proc, isolated)
            with _RUNNING_LOCK:
                _RUNNING.discard(proc)
    # Kill what is left first: without namespaces a student process that left the job's
    # process group can hold the pipe's write end (a node forked without exec), so the
    # reader would wait for an end of file that never comes, and could write report.json.
    sweep(token)
    reader.join(timeout=10)
    _keep_report(job_dir, reports)
    out_of_memory, peak = groups.out_of_memory(), groups.peak_mb()
    groups.remove()
    code = None if timed_out else proc.returncode
    return JobRun(code, timed_out, _tail(log, limits.output_kb * 1024),
                  time.monotonic() - started, isolated, out_of_memory, peak)


# The jobs running now: each is in a process group of its own (see enter), so a Ctrl-C of
# the grader does not reach them; the grader stops them with stop_jobs().
_RUNNING: set[subprocess.Popen[bytes]] = set()
_RUNNING_LOCK = threading.Lock()
_STOPPING = threading.Event()


def stop_jobs(stopping: bool = True) -> None:
    """Kill every running job and any that starts until `stop_jobs(False)` (the grader's
    Ctrl-C: until its worker threads have ended)."""
    with _RUNNING_LOCK:
        if not stopping:
            _STOPPING.clear()
            return
        _STOPPING.set()
        for proc in _RUNNING:
            with contextlib.suppress(OSError):
                proc.kill()


def _read_reports(fd: int, reports: list[bytes]) -> None:
    with os.fdopen(fd, 'rb') as pipe:
        for line in pipe:
            if line.endswith(b'\n'):
                reports.append(line)
                del reports[:-1]


def _keep_report(job_dir: Path, reports: list[bytes]) -> None:
    """job_dir/report.json is the job's last report through the pipe, never a file the
    submission left there."""
    target = job_dir / 'report.json'
    with contextlib.suppress(FileNotFoundError):
        target.unlink()
    if reports:
        target.write_bytes(reports[-1])


def _chown_tree(root: Path, uid: int) -> None:
    """The job folder to the job's uid (a root grader's job runs as that uid)."""
    os.chown(root, uid, uid)
    for folder, dirs, files in os.walk(root):
        for name in (*dirs, *files):
            with contextlib.suppress(OSError):
                os.chown(os.path.join(folder, name), uid, uid, follow_symlinks=False)


def _kill(proc: subprocess.Popen[bytes], isolated: bool) -> None:
    if proc.poll() is None:
        if isolated:
            proc.kill()  # unshare --kill-child: the namespace's PID 1 dies, then all of it
        else:
            with contextlib.suppress(OSError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.kill()
    proc.wait()


def sweep(token: str) -> list[str]:
    """Kill any process still carrying the job's token (outside namespaces, a student
    process that left the process group); the command lines of those killed."""
    import psutil

    killed = []
    for proc in psutil.process_iter():
        with contextlib.suppress(psutil.Error):
            if proc.environ().get(TOKEN_VAR) == token:
                killed.append(' '.join(proc.cmdline())[:200])
                proc.kill()
    return killed
