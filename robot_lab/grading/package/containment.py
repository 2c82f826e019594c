"""Whether this machine can fence a grading job in, what to do when it cannot, and the one
line the grader prints about it before the first job.

Issue 51: a grader that was not root, on a machine that refused namespaces (Ubuntu 24.04's
AppArmor rule, Docker's seccomp profile, Binder), ran students' code as the instructor —
no read-only machine, no network isolation — and said nothing. Now every grader without
namespaces refuses unless told `--no-sandbox`, and says why and how to allow them.

Measured as a second route, bubblewrap (`bwrap` 0.8, Debian 12) gains nothing here: it makes
the same namespaces through the same system calls, so where `unshare` is refused it is
refused too (`user.max_*_namespaces` = 0: ENOSPC for both; Docker's seccomp profile blocks
both), and on stock Ubuntu 24.04 its AppArmor profile (`bwrap-userns-restrict`) is only an
extra profile an administrator must load — as much work as the sysctl or a profile below.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess

from robot_lab.grading.package.rubric import Limits

__all__ = ['NO_NAMESPACES_VAR', 'NO_SANDBOX_VAR', 'container_line', 'containment_line',
           'namespace_problem',
           'namespaces_available', 'refusal', 'unshare_args']

NO_SANDBOX_VAR = 'ROBOT_LAB_GRADE_NO_SANDBOX'
# Set by a benchmark to measure jobs as if `unshare` were refused (never by the grader).
NO_NAMESPACES_VAR = 'ROBOT_LAB_GRADE_NO_NAMESPACES'
_NAMESPACES = ['--mount', '--propagation', 'private', '--net', '--ipc', '--pid', '--fork',
               '--kill-child', '--mount-proc']


def unshare_args() -> list[str]:
    """`unshare`'s options for a job: root needs no user namespace to make the others (it
    drops to a plain uid instead); anyone else makes them in a user namespace of its own."""
    return _NAMESPACES if os.geteuid() == 0 else ['--user', '--map-root-user', *_NAMESPACES]


@functools.cache
def namespace_problem() -> str | None:
    """Why a job's namespaces cannot be made here, in `unshare`'s own words (None: they can).

    Tried once per process (`namespace_problem.cache_clear()` to try again): a refusal
    is asked for its reason by the grader's message, and each try starts an `unshare`."""
    from robot_lab.linux import capabilities

    if os.environ.get(NO_NAMESPACES_VAR):
        return f'namespaces turned off by {NO_NAMESPACES_VAR}'
    if capabilities.disabled('namespaces'):
        return f'namespaces switched off ({capabilities.DISABLE_VARIABLE}=namespaces)'
    unshare = shutil.which('unshare')
    if unshare is None:
        return "no 'unshare' command (util-linux) on PATH"
    try:
        done = subprocess.run([unshare, *unshare_args(), 'true'], capture_output=True,
                              timeout=10)
    except subprocess.TimeoutExpired:
        return 'unshare did not finish in 10 s'
    except OSError as err:
        return f'unshare could not start: {err.strerror}'
    if done.returncode == 0:
        return None
    said = done.stderr.decode(errors='replace').strip().splitlines()
    return said[-1].strip() if said else f'unshare exited with code {done.returncode}'


def namespaces_available() -> bool:
    """True when `unshare` can give a job its own mount, network and PID namespaces here
    (and, for a grader that is not root, a user namespace to make them in); from
    namespace_problem's one try."""
    return namespace_problem() is None


def _advice() -> list[str]:
    """What would let this machine make namespaces, most specific first."""
    from robot_lab.linux.namespaces import restrictions

    found = restrictions()
    root = os.geteuid() == 0
    said = []
    if shutil.which('unshare') is None:
        said.append("install util-linux (it provides 'unshare')")
    if found.apparmor and not root:
        said.append("Ubuntu's AppArmor restricts user namespaces: `sudo sysctl "
                    'kernel.apparmor_restrict_unprivileged_userns=0`, or an AppArmor profile '
                    'with `userns,` for /usr/bin/unshare')
    if found.userns_clone_off and not root:
        said.append('`sudo sysctl kernel.unprivileged_userns_clone=1`')
    zero = [f'user.max_{kind}_namespaces=15000' for kind in found.zero_limits
            if kind != 'user' or not root]
    if zero:
        said.append(f"`sudo sysctl -w {' '.join(zero)}` (a limit of 0 allows none)")
    if found.seccomp:
        said.append('in a container, run it with `--security-opt seccomp=unconfined` '
                    '(Docker) or grade on the host')
    if not said:
        said.append('allow unprivileged user namespaces (`sysctl user.max_user_namespaces`, '
                    "`kernel.unprivileged_userns_clone`, Ubuntu's "
                    '`kernel.apparmor_restrict_unprivileged_userns`)')
    return said


def refusal() -> tuple[str, str] | None:
    """The grader's refusal (message, fix) when jobs cannot be contained, else None."""
    if namespaces_available():
        return None
    problem = namespace_problem() or 'namespaces were refused'
    who = 'root, with all its privileges' if os.geteuid() == 0 else f'you (uid {os.geteuid()})'
    message = (f"refusing to grade: this machine cannot make namespaces for the grading "
               f"jobs ({problem}), so students' code would run as {who}, able to read and "
               "write your files and reach the network")
    fix = '; or '.join(_advice()) + '; or pass --no-sandbox to grade without containment'
    return message, fix


def _cap(limits: Limits) -> str:
    """The limits; the whole job's memory only where a root grader can make a memory
    cgroup (robot_lab.grading.package.cgroups): elsewhere only each process is bounded."""
    from robot_lab.grading.package.cgroups import memory_cgroup_possible

    whole = (f' ({limits.job_memory_mb} MB for the whole job: a memory cgroup)'
             if memory_cgroup_possible() else '')
    return (f'limits {limits.cpu_seconds:g} s CPU, {limits.memory_mb} MB memory per '
            f'process{whole}, {limits.processes} processes, {limits.wall_seconds:g} s wall')


def container_line(limits: Limits, problem: str) -> str:
    """The line for a grader inside a throwaway container with no namespaces (Gradescope's:
    one per submission, discarded after it): the container is the sandbox, said so."""
    who = 'root' if os.geteuid() == 0 else f'uid {os.geteuid()}'
    return (f"containment: the container is the sandbox: namespaces are unavailable in it "
            f"({problem}), so the student's code runs as {who} in this container, with its "
            f'files and network; {_cap(limits)} and a sweep of its processes')


def containment_line(limits: Limits, no_sandbox: bool) -> str:
    """One line saying how each job will be contained (printed before the first job)."""
    cap = _cap(limits)
    if no_sandbox:
        who = 'root' if os.geteuid() == 0 else f'uid {os.geteuid()}'
        return (f"containment: NONE (--no-sandbox): students' code runs as {who}, with your "
                f'files and network; only {cap} and a sweep of its processes')
    from robot_lab.grading.package.confinement import JOB_USER, hidden_tops

    how = ('namespaces mount, pid, net, ipc (a root grader: unshare)' if os.geteuid() == 0
           else 'namespaces user, mount, pid, net, ipc (unshare --user)')
    hidden = ' '.join(str(p) for p in hidden_tops()) or 'none'
    return (f"containment: each job in its own {how}; runs as '{JOB_USER}' "
            '(uid 200000+domain, no capabilities); read-only machine, private /tmp, '
            f'hidden {hidden}; loopback-only network; {cap}')
