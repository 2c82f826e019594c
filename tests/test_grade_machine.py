"""A grading job looks like a machine to honest code, and is contained whoever grades
(issue 51).

A job's uid had no passwd entry: a correct package whose nodes called `getpass.getuser()`
lost 7 of 13 points. And a grader that was not root fell back to no sandbox at all, with
nothing said, where the machine refused namespaces. Here, for real: a probe job run by a
root grader and by an unprivileged one (a uid with no account, under `setpriv`) sees its
own user, home, locale, hosts, /dev and /proc, and no more of the machine; a class graded
as that user scores full marks; and where namespaces are refused (every
`user.max_*_namespaces` set to 0 inside a user namespace of the test's own), the grader
refuses, root or not, says why and what to do, and grades only when told `--no-sandbox`.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import BIN, REPO
from test_grade_contained import DATA, _looks_around, _odd_entries

from robot_lab.errors import RobotLabError
from robot_lab.grading.package import containment
from robot_lab.grading.package.cgroups import memory_cgroup_possible
from robot_lab.grading.package.confinement import JOB_USER, job_uid, machine_files
from robot_lab.grading.package.containment import NO_SANDBOX_VAR, namespace_problem
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import check_can_contain, namespaces_available, run_job

TEST_UID = 64123  # no account on this machine: neither the grader nor its jobs need one
DOMAIN = 11
real = pytest.mark.skipif(
    os.geteuid() != 0 or not shutil.which('setpriv') or not namespaces_available(),
    reason='needs root (to become another user and to limit namespaces) and namespaces')


def test_the_jobs_accounts_replace_a_namesake_and_keep_the_machines() -> None:
    passwd = ('root:x:0:0:root:/root:/bin/bash\nstudent:x:1000:1000::/home/student:/bin/sh\n'
              'ghost:x:200011:5::/:/bin/false\nnobody:x:65534:65534::/nonexistent:/bin/false\n')
    group = 'root:x:0:\nstudent:x:1000:\nnogroup:x:65534:\n'
    files = machine_files(job_uid(DOMAIN), Path('/jobs/j1/home'), passwd, group, 'lab-pc')
    users = [line.split(':') for line in files['/etc/passwd'].splitlines()]
    assert [u[0] for u in users] == ['root', 'nobody', JOB_USER]
    assert users[-1][2:4] == ['200011', '200011'] and users[-1][5] == '/jobs/j1/home'
    groups = [line.split(':')[:3] for line in files['/etc/group'].splitlines()]
    assert groups == [['root', 'x', '0'], ['nogroup', 'x', '65534'], [JOB_USER, 'x', '200011']]
    hosts = files['/etc/hosts'].splitlines()
    assert '127.0.0.1\tlocalhost' in hosts and '127.0.1.1\tlab-pc' in hosts


def test_the_layers_switch_makes_the_grader_refuse(monkeypatch: pytest.MonkeyPatch) -> None:
    """`ROBOT_LAB_DISABLE=namespaces` (robot_lab.linux.capabilities) is a machine without
    them to the grader: it refuses, and --no-sandbox says that nothing contains the jobs."""
    monkeypatch.setenv('ROBOT_LAB_DISABLE', 'namespaces')
    monkeypatch.setenv(NO_SANDBOX_VAR, '')  # restored by monkeypatch: check_can_contain sets it
    namespace_problem.cache_clear()
    try:
        with pytest.raises(RobotLabError) as refused:
            check_can_contain()
        assert 'ROBOT_LAB_DISABLE=namespaces' in refused.value.message
        assert '--no-sandbox' in (refused.value.fix or '')
        line = check_can_contain(no_sandbox=True, limits=Limits(processes=64))
        assert line.startswith('containment: NONE (--no-sandbox)') and '64 processes' in line
    finally:
        namespace_problem.cache_clear()


def test_a_refusal_runs_unshare_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The grader asks whether namespaces can be made, then why not: one `unshare` run."""
    runs: list[list[str]] = []

    def refused(cmd: list[str], **kwargs: Any) -> subprocess.CompletedProcess[bytes]:
        runs.append(cmd)
        return subprocess.CompletedProcess(cmd, 1, b'', b'unshare: unshare failed: '
                                           b'Operation not permitted\n')

    for name in ('ROBOT_LAB_DISABLE', containment.NO_NAMESPACES_VAR):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(shutil, 'which', lambda name: '/usr/bin/' + name)
    monkeypatch.setattr(subprocess, 'run', refused)
    namespace_problem.cache_clear()
    try:
        assert not containment.namespaces_available()
        said = containment.refusal()
        assert said is not None and '(unshare: unshare failed: Operation not permitted)' in said[0]
        assert not containment.namespaces_available()
        assert len(runs) == 1 and runs[0][0] == '/usr/bin/unshare', runs
    finally:
        namespace_problem.cache_clear()


# What a job sees, from inside: run after `enter`, as every grading job is. Each attempt
# gives its result or the error it met; the test judges them.
PROBE = """
import getpass, grp, json, locale, os, pwd, resource, socket, sys
from pathlib import Path
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import enter

job = Path(sys.argv[-1])
enter(Limits(processes=64, memory_mb=1024), bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')),
      job)


def attempt(action):
    try:
        return action()
    except Exception as err:
        return f'{type(err).__name__}: {err}'


def write(path):
    with open(path, 'w') as f:
        f.write('x')
    return 'written'


def status(field):
    return next(line.split()[1] for line in open('/proc/self/status')
                if line.startswith(field + ':'))


def connect():
    socket.create_connection(('127.0.0.1', int(os.environ['PROBE_PORT'])), 2).close()
    return 'connected'


seen = {
    'uid': os.getuid(), 'gid': os.getgid(), 'getuser': attempt(getpass.getuser),
    'passwd': attempt(lambda: list(pwd.getpwuid(os.getuid()))[:6]),
    'group': attempt(lambda: grp.getgrgid(os.getgid()).gr_name),
    'env': [os.environ.get(k) for k in ('HOME', 'USER', 'LOGNAME')],
    'home': os.path.expanduser('~'),
    'home_write': attempt(lambda: write(os.path.expanduser('~/.probe'))),
    'locale': attempt(lambda: locale.setlocale(locale.LC_ALL, '')),
    'encoding': locale.getpreferredencoding(),
    'localhost': attempt(lambda: socket.gethostbyname('localhost')),
    'hostname': attempt(lambda: socket.gethostbyname(socket.gethostname())),
    'dev_null': attempt(lambda: write('/dev/null')),
    'urandom': attempt(lambda: len(open('/dev/urandom', 'rb').read(8))),
    'proc_self': attempt(lambda: int(status('Pid')) == os.getpid()
                         and os.path.realpath('/proc/self/cwd') == str(job.resolve())),
    'passwd_write': attempt(lambda: write('/etc/passwd')),
    'system_write': attempt(lambda: write('/usr/robot_lab_probe')),
    'tmp': sorted(os.listdir('/tmp')), 'tmp_write': attempt(lambda: write('/tmp/mine')),
    'sibling': attempt(lambda: open(job.parent / 'secret').read()),
    'interfaces': [name for _, name in socket.if_nameindex()], 'connect': attempt(connect),
    'processes': len([p for p in os.listdir('/proc') if p.isdigit()]),
    'caps': status('CapEff'), 'no_new_privs': status('NoNewPrivs'),
    'limits': [resource.getrlimit(resource.RLIMIT_DATA)[0] >> 20,
               resource.getrlimit(resource.RLIMIT_AS)[0] >> 20,
               resource.getrlimit(resource.RLIMIT_NPROC)[0]],
}
print('PROBE ' + json.dumps(seen), flush=True)
"""


def _probe_output(output: str) -> dict[str, Any]:
    line = next((x for x in output.splitlines() if x.startswith('PROBE ')), None)
    assert line is not None, output
    seen: dict[str, Any] = json.loads(line[len('PROBE '):])
    return seen


def _judge(seen: dict[str, Any], job: Path) -> None:
    """The same promises whoever runs the grader."""
    uid, home = job_uid(DOMAIN), str(job.resolve() / 'home')
    assert (seen['uid'], seen['gid']) == (uid, uid), seen
    assert seen['getuser'] == JOB_USER and seen['group'] == JOB_USER, seen
    assert seen['passwd'] == [JOB_USER, 'x', uid, uid, 'robot_lab grading job', home], seen
    assert seen['env'] == [home, JOB_USER, JOB_USER] and seen['home'] == home, seen
    assert seen['home_write'] == 'written', seen
    assert seen['locale'] == 'C.UTF-8' and seen['encoding'] == 'UTF-8', seen
    assert seen['localhost'] == '127.0.0.1' and seen['hostname'].startswith('127.'), seen
    assert seen['dev_null'] == 'written' and seen['urandom'] == 8, seen
    assert seen['proc_self'] is True, seen
    # Contained: a read-only machine (its own passwd too), a private /tmp, no other
    # hand-in, only a loopback of its own, its own processes, no capabilities, limits.
    assert 'Read-only file system' in seen['passwd_write'], seen
    assert ('Read-only file system' in seen['system_write']
            or 'Permission denied' in seen['system_write']), seen
    # /tmp shows the folders on the way to the job and to the kit (a clone under /tmp, as a
    # CI checkout may be), which the job must read; nothing else.
    kit = (Path(__file__).resolve().parents[1], Path(sys.prefix).resolve())
    on_the_way = sorted({p.parts[2] for p in (job.resolve(), *kit)
                         if len(p.parts) > 2 and p.parts[1] == 'tmp'})
    assert seen['tmp'] == on_the_way and seen['tmp_write'] == 'written', seen  # nothing else
    assert seen['sibling'].startswith('FileNotFoundError'), seen
    assert seen['interfaces'] == ['lo'], seen
    assert seen['connect'].startswith('ConnectionRefusedError'), seen
    assert seen['processes'] == 2, seen  # the namespace's init and the job
    assert seen['caps'] == '0000000000000000' and seen['no_new_privs'] == '1', seen
    assert seen['limits'] == [1024, 4096, 64], seen


@pytest.fixture
def listener() -> Iterator[socket.socket]:
    """A TCP port on the host's loopback that no job may reach."""
    sock = socket.socket()
    sock.bind(('127.0.0.1', 0))
    sock.listen(4)
    yield sock
    sock.close()


@pytest.fixture
def user_dir() -> Iterator[Path]:
    """A folder the test user owns (pytest's own tmp folders are root's alone)."""
    path = Path(tempfile.mkdtemp(prefix='robot_lab_user_'))
    (path / 'home').mkdir()
    os.chown(path, TEST_UID, TEST_UID)
    os.chown(path / 'home', TEST_UID, TEST_UID)
    yield path
    shutil.rmtree(path, ignore_errors=True)


# Runs COMMAND as TEST_UID, from a mount namespace of its own (made by `unshare --mount`):
# where the interpreter, the venv or the repository lies under a folder others may not enter
# (/root/.pyenv here), that folder is covered there by one that holds only them. With
# --no-namespaces, in a user namespace of its own whose every `user.max_*_namespaces` is 0
# first: neither its root nor TEST_UID can make a namespace there, and nothing outside is
# touched.
AS_USER = """
import ctypes, os, subprocess, sys, tempfile
from pathlib import Path

args = sys.argv[1:]
no_namespaces = args[0] == '--no-namespaces'
uid, repo, command = int(args[1]), args[2], args[3:]
# What the user must reach: the Python the venv runs on, the venv, the repository.
wanted = sorted({Path(p).resolve() for p in (sys.base_prefix, sys.prefix, repo)},
                key=lambda p: len(p.parts))
wanted = [p for i, p in enumerate(wanted) if not any(p.is_relative_to(q) for q in wanted[:i])]
covers = {}
for path in wanted:
    closed = [a for a in reversed(path.parents) if a != Path('/') and not a.stat().st_mode & 1]
    if closed:
        covers.setdefault(closed[0], []).append(path)
for closed, paths in covers.items():
    kept = [(path, tempfile.mkdtemp()) for path in paths]
    for path, keep in kept:
        subprocess.run(['mount', '--bind', str(path), keep], check=True)
    subprocess.run(['mount', '-t', 'tmpfs', '-o', 'mode=755', 'tmpfs', str(closed)], check=True)
    for path, keep in kept:
        path.mkdir(parents=True)
        subprocess.run(['mount', '--bind', keep, str(path)], check=True)
        subprocess.run(['umount', keep], check=True)
        os.rmdir(keep)
become = ['setpriv', f'--reuid={uid}', f'--regid={uid}', '--clear-groups', *command]
if not no_namespaces:
    os.execvp(become[0], become)
libc = ctypes.CDLL(None, use_errno=True)
unshared_r, unshared_w = os.pipe()
mapped_r, mapped_w = os.pipe()
child = os.fork()
if child == 0:
    if libc.unshare(0x10000000) != 0:  # CLONE_NEWUSER
        os._exit(90)
    os.write(unshared_w, b'1')
    os.read(mapped_r, 1)
    os.setresgid(0, 0, 0)
    os.setresuid(0, 0, 0)
    for limit in Path('/proc/sys/user').glob('max_*_namespaces'):
        limit.write_text('0')
    os.execvp(become[0], become)
assert os.read(unshared_r, 1) == b'1'
for kind in ('uid_map', 'gid_map'):
    Path(f'/proc/{child}/{kind}').write_text('0 0 65536\\n')
os.write(mapped_w, b'1')
sys.exit(os.waitstatus_to_exitcode(os.waitpid(child, 0)[1]))
"""


def _as_user(command: list[str], home: Path, env: dict[str, str] | None = None,
             no_namespaces: bool = False, timeout: float = 120,
             uid: int = TEST_UID) -> subprocess.CompletedProcess[str]:
    wrapper = ['unshare', '--mount', '--propagation', 'private', sys.executable, '-c',
               AS_USER, '--no-namespaces' if no_namespaces else '--', str(uid), str(REPO),
               *command]
    full = {**os.environ, 'HOME': str(home), 'PATH': f'{BIN}:{os.environ["PATH"]}',
            **(env or {})}
    for name in ('USER', 'LOGNAME', 'ROBOT_LAB_GRADE_NO_SANDBOX'):
        full.pop(name, None)
    return subprocess.run(wrapper, capture_output=True, text=True, timeout=timeout,
                          env=full, check=False)


GRADER = """
import sys
from pathlib import Path
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import run_job
run = run_job(Path(sys.argv[1]), int(sys.argv[2]), Limits(wall_seconds=60), 'tok-probe',
              argv=['-c', sys.argv[3]])
print(run.output, 'isolated' if run.isolated else 'NOT ISOLATED', flush=True)
"""


@pytest.mark.skipif(not namespaces_available(), reason='no namespaces here')
def test_a_job_of_this_grader_sees_a_machine_and_no_more(
        tmp_path: Path, listener: socket.socket) -> None:
    job = tmp_path / 'job'
    job.mkdir()
    (tmp_path / 'secret').write_text('another hand-in')
    env = {'PROBE_PORT': str(listener.getsockname()[1]), 'LC_ALL': 'xx_XX.UTF-8'}
    os.environ.update(env)  # an instructor's terminal locale the job must not inherit
    try:
        run = run_job(job, DOMAIN, Limits(wall_seconds=60), 'tok-probe', argv=['-c', PROBE])
    finally:
        for name in env:
            del os.environ[name]
    assert run.isolated and run.returncode == 0, run.output
    _judge(_probe_output(run.output), job)


@real
def test_a_job_of_a_grader_that_is_not_root_sees_the_same(
        user_dir: Path, listener: socket.socket) -> None:
    job = user_dir / 'job'
    job.mkdir()
    os.chown(job, TEST_UID, TEST_UID)
    (user_dir / 'secret').write_text('another hand-in')
    done = _as_user([sys.executable, '-c', GRADER, str(job), str(DOMAIN), PROBE],
                    user_dir / 'home', {'PROBE_PORT': str(listener.getsockname()[1])})
    assert done.returncode == 0 and 'isolated' in done.stdout, done.stdout + done.stderr
    _judge(_probe_output(done.stdout), job)


@real
def test_a_grader_that_is_not_root_gives_a_curious_package_full_marks(
        user_dir: Path, ros_domain: int) -> None:
    """The whole grader as an unprivileged user: a correct package whose every node asks
    who and where it is (before issue 51: 6 of 13, as root)."""
    shutil.copytree(DATA / 'reference', user_dir / 'class' / 'curious')
    _looks_around(user_dir / 'class' / 'curious')
    subprocess.run(['chown', '-R', f'{TEST_UID}:{TEST_UID}', str(user_dir)], check=True)
    done = _as_user([str(BIN / 'robot-lab'), 'grade', str(user_dir / 'class'), '--lab',
                     'ch6-lab1', '-o', str(user_dir / 'out')], user_dir / 'home',
                    {'ROS_DOMAIN_ID': str(ros_domain)}, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    [line] = [x for x in done.stderr.splitlines() if x.startswith('containment:')]
    assert 'unshare --user' in line and f"runs as '{JOB_USER}'" in line, line
    assert 'curious: 13/13' in done.stdout, (user_dir / 'out' / 'feedback' /
                                             'curious.md').read_text()


@real
@pytest.mark.parametrize('uid', [0, TEST_UID], ids=['root', 'user'])
def test_without_namespaces_the_grader_refuses_unless_told(user_dir: Path, uid: int) -> None:
    """Namespaces refused for real: the grader says why and what to do, in one line, and
    grades only with --no-sandbox, saying first that nothing contains the jobs."""
    _odd_entries(user_dir / 'class')  # entries without a package: no job is started
    subprocess.run(['chown', '-R', f'{TEST_UID}:{TEST_UID}', str(user_dir)], check=True)
    grade = [str(BIN / 'robot-lab'), 'grade', str(user_dir / 'class'), '--lab', 'ch6-lab1',
             '-o', str(user_dir / 'out')]
    refused = _as_user(grade, user_dir / 'home', no_namespaces=True, uid=uid)
    assert refused.returncode != 0 and refused.stdout == '', refused.stdout
    [said] = refused.stderr.strip().splitlines()
    assert 'refusing to grade' in said and 'cannot make namespaces' in said, said
    assert 'No space left on device' in said, said  # unshare's own words
    assert 'user.max_mnt_namespaces=15000' in said and '--no-sandbox' in said, said
    assert ('user.max_user_namespaces' in said) == (uid != 0), said
    assert ('as root' in said) == (uid == 0) and not (user_dir / 'out').exists(), said
    done = _as_user([*grade, '--no-sandbox'], user_dir / 'home', no_namespaces=True, uid=uid)
    assert done.returncode == 0, done.stderr
    first = done.stderr.splitlines()[0]
    assert first.startswith('containment: NONE (--no-sandbox)'), done.stderr
    assert ('runs as root' if uid == 0 else f'runs as uid {TEST_UID}') in first, first
    assert (user_dir / 'out' / 'grades.csv').read_text().count('\n') == 5
    print(first)  # the line on a host without namespaces, for the record (pytest -s)



def _graded_by(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, job: str, domain: int,
               limits: str = '') -> Any:
    """The reference package graded by the grader, for the build check only, with `job`
    (a Python program) run in the sandbox as the job; the student's report."""
    from robot_lab.grading.package import grade
    from robot_lab.grading.package.rubric import load_rubric
    from robot_lab.grading.package.submission import find_submissions

    rubric_file = tmp_path / 'builds.yaml'
    rubric_file.write_text('lab: ch6-lab1\ntitle: builds only\nchecks:\n'
                           '  - id: builds\n    name: The package builds with colcon\n'
                           '    points: 2\n' + limits)
    shutil.copytree(DATA / 'reference', tmp_path / 'class' / 'alice')
    real_run_job = grade.run_job
    monkeypatch.setattr(grade, 'run_job', lambda *args: real_run_job(*args, argv=['-c', job]))
    [entry] = find_submissions(tmp_path / 'class')
    return grade.grade_package(entry, load_rubric(rubric_file), domain)


# The job, run as always (`python -m robot_lab.grading.package.job JOBDIR`), with the one
# mount of its own passwd refused as the machine would refuse it.
PASSWD_REFUSED = """
import runpy
from robot_lab.grading.package import confinement
confinement._mount_machine_files = lambda uid, home: ['/etc/passwd: Device or resource busy']
runpy.run_module('robot_lab.grading.package.job', run_name='__main__')
"""


@pytest.mark.skipif(not namespaces_available(), reason='no namespaces here')
def test_a_job_the_sandbox_could_not_give_its_passwd_says_so(
        tmp_path: Path, ros_domain: int, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """Seen once on a loaded host: a job's nodes missed their passwd entry (they saw the
    machine's) and lost points with nothing said why. The grader's fault is told to the
    instructor at once and kept in the student's feedback as not the student's."""
    report = _graded_by(tmp_path, monkeypatch, PASSWD_REFUSED, ros_domain)
    assert report.score == 2, report.markdown()
    [note] = report.notes
    assert note == ('the grader could not set up /etc/passwd: Device or resource busy (not '
                    'your fault: code that needs it may have failed)'), note
    assert f'> **Sandbox:** {note}' in report.markdown()
    said = capsys.readouterr().err
    assert f'warning: alice: {note}\n' in said, said


# Inside a job, under the rubric's default limits: an honest node whose executor runs 48
# callbacks at once (MultiThreadedExecutor() on a 48-core grading server), 500 MB that
# fits, and two hostile allocations that do not (private, and shared, which only the
# address-space backstop counts).
MEMORY = """
import json, mmap, os, sys, threading
from pathlib import Path
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import enter

enter(Limits(), bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')), Path(sys.argv[-1]))
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor

MB = 1 << 20
rclpy.init()
node = rclpy.create_node('threaded')
together = threading.Barrier(48, timeout=20)
met = []


def callback():
    try:
        together.wait()
        met.append(1)
    except threading.BrokenBarrierError:
        pass


timer = node.create_timer(0.001, callback, ReentrantCallbackGroup())
executor = MultiThreadedExecutor(num_threads=48)
executor.add_node(node)
spinning = threading.Thread(target=executor.spin, daemon=True)
spinning.start()
seen = {}
try:
    together.wait()
    seen['threads'] = 'met'
except threading.BrokenBarrierError:
    seen['threads'] = 'broken'
timer.cancel()
executor.shutdown()


def attempt(action):
    try:
        return action()
    except (MemoryError, OSError) as err:
        return type(err).__name__


seen['half'] = attempt(lambda: len(bytearray(500 * MB)) // MB)
seen['private'] = attempt(lambda: len(bytearray(1600 * MB)) // MB)
seen['shared'] = attempt(lambda: len(mmap.mmap(-1, 7000 * MB)) // MB)
print('MEMORY ' + json.dumps(seen), flush=True)
os._exit(0)
"""


@pytest.mark.skipif(not namespaces_available(), reason='no namespaces here')
def test_a_jobs_memory_is_what_it_holds_not_what_it_reserves(tmp_path: Path) -> None:
    """The limit was 1.5 GB of address space, which an rclpy node's threads and malloc
    arenas reserve without using: a MultiThreadedExecutor with 32 threads could not start
    them. Memory is now what a process holds (RLIMIT_DATA), address space a backstop."""
    (tmp_path / 'job').mkdir()
    run = run_job(tmp_path / 'job', DOMAIN, Limits(wall_seconds=90), 'tok-memory',
                  argv=['-c', MEMORY])
    line = next((x for x in run.output.splitlines() if x.startswith('MEMORY ')), None)
    assert run.returncode == 0 and line is not None, run.output
    seen = json.loads(line[len('MEMORY '):])
    assert seen == {'threads': 'met', 'half': 500, 'private': 'MemoryError',
                    'shared': 'OSError'}, run.output


# A hostile job within every per-process limit: 4 processes that each hold 300 MB (every
# page written), together past the job's 600 MB. It says which groups it is in, and how
# each child ended: 0 once it held its 300 MB and was let go, or -9 (killed).
MEMORY_HOG = """
import json, os, select, sys
from pathlib import Path
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import CGROUP_VAR, enter

enter(Limits(job_memory_mb=600), bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')),
      Path(sys.argv[-1]))
print('GROUPS ' + json.dumps(os.environ[CGROUP_VAR].split(os.pathsep)), flush=True)
ready_r, ready_w = os.pipe()
hold_r, hold_w = os.pipe()
children = {}
for _ in range(4):
    pid = os.fork()
    if pid == 0:
        os.close(ready_r)
        os.close(hold_w)
        held = b'x' * (300 << 20)  # written, so resident: not a lazy zero page
        os.write(ready_w, b'%d ' % os.getpid())
        os.read(hold_r, 1)  # until the parent has seen every child hold or die
        os._exit(0)
    children[os.pidfd_open(pid)] = pid
os.close(ready_w)
os.close(hold_r)
holding, ended = set(), []
while len(holding) + len(ended) < 4:  # each child holds its 300 MB or was killed
    ready, _, _ = select.select([ready_r, *children], [], [])
    for fd in ready:
        if fd == ready_r:
            holding.update(int(p) for p in os.read(ready_r, 4096).split())
        else:
            pid = children.pop(fd)
            ended.append(os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]))
            holding.discard(pid)
# A holder may have been killed for a later child and not yet have exited: its end is
# known once it is reaped.
os.close(hold_w)
ended += [os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) for pid in children.values()]
print('CHILDREN ' + json.dumps(sorted(ended)), flush=True)
"""

memory_cgroup = pytest.mark.skipif(
    os.geteuid() != 0 or not memory_cgroup_possible(),
    reason='needs a root grader that can make a memory cgroup')


def _said(output: str, tag: str) -> Any:
    line = next((x for x in output.splitlines() if x.startswith(f'{tag} ')), None)
    assert line is not None, output
    return json.loads(line[len(tag) + 1:])


@memory_cgroup
def test_a_job_past_its_memory_in_all_is_stopped_by_the_kernel(tmp_path: Path) -> None:
    """Memory was bounded per process only: 250 processes of 1.4 GB each would take the
    grading host's RAM. A job's processes together are now bounded by a memory cgroup:
    past it the kernel kills the job's own processes, the grader lives on and says why,
    and the groups are gone afterwards."""
    (tmp_path / 'job').mkdir()
    run = run_job(tmp_path / 'job', DOMAIN, Limits(job_memory_mb=600, wall_seconds=60),
                  'tok-memory-hog', argv=['-c', MEMORY_HOG])
    assert run.returncode == 0, run.output
    ended = _said(run.output, 'CHILDREN')
    assert ended in ([-9, -9, -9, 0], [-9] * 4), run.output  # 2 x 300 MB > 600 MB
    assert run.out_of_memory and run.memory_peak_mb is not None, run
    assert 500 < run.memory_peak_mb <= 600, run.memory_peak_mb
    groups = [Path(g) for g in _said(run.output, 'GROUPS')]
    assert any(g.name == 'robot_lab-tok-memory-hog' for g in groups), groups
    assert not [g for g in groups if g.exists()], groups


@memory_cgroup
def test_the_feedback_says_the_kernel_stopped_a_job_past_its_memory(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The student reads that the submission as a whole used too much memory, not that a
    grading job ended with code -9."""
    report = _graded_by(tmp_path, monkeypatch, MEMORY_HOG + 'os._exit(1)\n', DOMAIN,
                        'limits:\n  job_memory_mb: 600\n  wall_seconds: 60\n')
    assert report.status == 'error' and report.score == 0, report.markdown()
    assert report.error == ('the submission used more than 600 MB of memory in all (its '
                            'processes together); the kernel stopped it; checks not reached '
                            'score 0'), report.error
    assert f'Grading ended early (error): {report.error}' in report.markdown()


def test_the_rubrics_bound_a_jobs_memory_in_all_and_refuse_a_bad_limit(
        tmp_path: Path) -> None:
    from robot_lab.grading.package.rubric import load_rubric, rubric_path

    for lab in ('ch6-lab1', 'ch7-description', 'ch8-sim', 'lab1.3'):
        assert load_rubric(rubric_path(lab)).limits.job_memory_mb == 4096
    bad = tmp_path / 'bad.yaml'
    bad.write_text('lab: ch6-lab1\nchecks:\n  - id: builds\nlimits:\n  memory_mb: 1500\n'
                   '  job_memory_mb: 4 GB\n')
    with pytest.raises(RobotLabError) as refused:
        load_rubric(bad)
    assert refused.value.line == 6, refused.value
    assert refused.value.message == "limits: job_memory_mb must be a whole number > 0, not '4 GB'"
    assert refused.value.fix == 'write e.g. `job_memory_mb: 4096`'


def test_the_containment_line_names_the_jobs_memory_in_all_only_where_it_applies(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from robot_lab.grading.package import cgroups

    whole = '1500 MB memory per process (600 MB for the whole job: a memory cgroup)'
    line = containment.containment_line(Limits(job_memory_mb=600), no_sandbox=True)
    assert (whole in line) == cgroups.memory_cgroup_possible(), line
    monkeypatch.setattr(cgroups.os, 'geteuid', lambda: 1000)  # a grader that is not root
    assert not cgroups.job_cgroups('tok-user', Limits()).paths
    line = containment.containment_line(Limits(job_memory_mb=600), no_sandbox=True)
    assert '1500 MB memory per process, 256 processes' in line, line
