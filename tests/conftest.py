"""Shared test set-up: loopback-only DDS, a distinct ROS_DOMAIN_ID per test module,
and real node processes that are always stopped (and die with pytest if it is killed)."""

from __future__ import annotations

import contextlib
import fcntl
import os
import queue
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import psutil
import pytest

from robot_lab.domain import JOB_POOL_VARIABLE
from robot_lab.env import apply_ros_defaults
from robot_lab.grading.course import first_of_chain, run_workspace
from robot_lab.graph.daemon import AUTOSTART_VARIABLE
from robot_lab.process import spawn, stop

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
SHARED = REPO.parent / 'shared'

# Domain IDs: a base per pytest run (ROBOT_LAB_TEST_DOMAIN_BASE), one per module after it.
_BASE = int(os.environ.get('ROBOT_LAB_TEST_DOMAIN_BASE', '30'))

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
# Set before the kit's defaults, which would otherwise give the tester's own domain from
# the host registry (robot_lab/domain.py); every module sets its own below anyway.
os.environ['ROS_DOMAIN_ID'] = str(_BASE % 100 + 1)
apply_ros_defaults()
# Job domains (grading jobs, autograded kernels: robot_lab/domain.py leases them from a
# registry). A registry knows only its own leases, and some tests book jobs in a registry of
# their own, so each registry gets a part of 215-232 that no other hands out: two jobs in
# one domain hear each other's nodes (an unanswered exercise passed a check on another
# test's graded answer). The run's own registry takes the first part.
JOB_POOLS = {'run': '215-226', 'docs_console': '227-229', 'grading_apart': '230-232'}
os.environ[JOB_POOL_VARIABLE] = JOB_POOLS['run']
# Graph verbs start no daemon of their own here (one per test domain would outlive the run);
# tests/test_graph_fresh.py turns it on where it checks it.
os.environ[AUTOSTART_VARIABLE] = '0'

# Where each run's domains go (offsets from the base; `./kit test` uses base 0). Modules run
# a few at a time (`./kit test` runs pytest-xdist workers), so a module leases a domain of
# its own for as long as it runs, and so has everything else that runs ROS beside them:
#   1       nothing leased: every worker's default before a module leases one (above), and
#           the first user domain the host registry gives (a Lab terminal's, `./kit start`'s)
#   2-50, 55-59, 71-76   test modules (leased, see `_lease_domain`)
#   51-54, 60   nbval's notebooks 09-12 and 13 (robot_lab/grading/course.py)
#   61-69   nbval's notebooks 00-08 (lesson n: 61 + n, robot_lab/grading/course.py)
#   70      exercise notebooks under nbgrader (tests/test_nbgrader.py)
#   77-79   the browser mistake tests' JupyterLab kernels (lessons 01-03: 76 + lesson)
#   80-93   the browser course tests' JupyterLab kernels (80 + lesson; 93 is also the pool of
#           tests/test_domains.py, whose users run ROS in a network namespace of their own)
#   93-101  the Unix users of tests/test_domains.py (their registry's pool)
_MODULE_SLOTS = [*range(2, 51), *range(55, 60), *range(71, 77)]
# Leases are file locks, shared by every pytest on this host (and /tmp): two runs at once
# take different domains too. A lock dies with its process, even after kill -9.
_LEASES = Path(tempfile.gettempdir()) / f'robot_lab-test-domains-{os.getuid()}'
_ros_modules: set[str] = set()


def _identity(kind: str, path: str, field: str) -> str:
    """Which network namespace (its inode) or /dev/shm (its device) this run shares."""
    try:
        return f'{kind}{getattr(os.stat(path), field)}'
    except OSError:  # no such thing here: every run shares the one claim of its kind
        return kind


_HOST_CLAIM: list[Any] = []  # the open lock files that hold this run's claim (controller)


def pytest_configure(config: pytest.Config) -> None:
    """One kit test run per host: the layout above leases module domains from every run, but
    its fixed domains (nbval's, the browser kernels', nbgrader's) belong to no lease, so two
    runs at once (different bases) can put a kernel of one in a domain the other leased for
    a module, which then sees a stranger's nodes. Fast DDS also locks its shared-memory
    ports in /dev/shm by port number, whatever the network. Refuse a second run that shares
    either the network namespace or /dev/shm, and say how to run both."""
    if os.environ.get('PYTEST_XDIST_WORKER') or config.option.collectonly:
        return  # a worker of the run that made the claim, or nothing will run
    _LEASES.mkdir(mode=0o700, exist_ok=True)
    for shared in (_identity('net', '/proc/self/ns/net', 'st_ino'),
                   _identity('shm', '/dev/shm', 'st_dev')):
        claim = open(_LEASES / f'run-{shared}.lock', 'a+')  # noqa: SIM115 - held by the run
        try:
            fcntl.flock(claim, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            claim.seek(0)
            holder = claim.read().strip() or 'another process'
            claim.close()
            raise pytest.UsageError(
                f"tests/conftest.py: another robot_lab test run ({holder}) is using this host's "
                "ROS domains; two at once would hear each other's nodes. Wait for it, or run "
                'this one with a network and a /dev/shm of its own: unshare --net --mount sh -c '
                "'ip link set lo up && mount -t tmpfs tmpfs /dev/shm && ./kit test'") from None
        claim.seek(0)
        claim.truncate()
        claim.write(f'pid {os.getpid()}, {REPO}')
        claim.flush()
        _HOST_CLAIM.append(claim)


def _fresh_run_workspace() -> None:
    """Remove the workspace this process's notebook kernels build in (nbval's lessons), if
    any: each run starts from an empty one, and /tmp does not fill with old runs' builds."""
    shutil.rmtree(run_workspace(os.getpid()), ignore_errors=True)


def pytest_sessionstart(session: pytest.Session) -> None:
    _fresh_run_workspace()  # one a crashed run left under this pid


def pytest_sessionfinish(session: pytest.Session) -> None:
    _fresh_run_workspace()


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_setup(item: pytest.Item) -> Any:
    """A notebook's kernel (started as nbval sets up its first cell) keeps a graph daemon as a
    student's does (grading.setup): it ends with the kernel, so nothing outlives the run, and
    the notebook's `!ros2` commands answer warm, as they do for a student."""
    if not item.nodeid.startswith('notebooks/'):
        return (yield)
    os.environ[AUTOSTART_VARIABLE] = '1'
    try:
        return (yield)
    finally:
        os.environ[AUTOSTART_VARIABLE] = '0'


def domain_at(offset: int) -> int:
    """The domain at `offset` of this run's layout (above), wrapped into 1-101."""
    return (_BASE + offset - 1) % 101 + 1


# Groups that take longest go to the workers first (the scheduler below hands groups out in
# collection order), so the run does not end waiting on one of them. Longest first, as
# `./kit test --durations=60` measured them (each a group's summed seconds, idle host).
_SLOW_FIRST = ('tests/browser/test_browser_course.py',  # ~480 s idle: the course in Chromium
               'tests/test_mistake_path.py',        # ~360 s: ladders 01-06, then Run All again
               'tests/test_mistake_path_capstone.py',  # ~300 s: the same for 07-08
               'tests/test_mistake_path_description.py',  # ~110 s: 12's ladders, Run All again
               'tests/test_mistake_path_simulation.py',  # 13's ladders, Run All again
               'tests/test_mistake_path_tf2.py',    # ~200 s: the same for 11
               'tests/test_grade_package.py',       # ~230 s: one class graded
               'tests/test_docs_console.py',        # ~180 s: the nbgrader loop as printed
               'tests/browser/test_browser_mistakes.py',  # ~160 s: 01-03 in Chromium
               'notebooks/01',                      # nbval: lessons 01-06, ~51 s
               'notebooks/11',                      # ~75 s: tf2 on turtlesim
               'notebooks/10', 'notebooks/07',      # ~38 s and ~29 s
               'notebooks/12',                      # ~50 s: URDF, tf2 (12_robot_description)
               'notebooks/13',                      # the simulator (13_simulation)
               'notebooks/09', 'notebooks/08', 'notebooks/00',
               'tests/test_grade_contained.py', 'tests/test_grading.py',
               'tests/test_cli_inspect.py', 'tests/test_lab_bench.py',
               'tests/test_grade_workflow.py', 'tests/test_tutorials.py',
               'tests/test_nbgrader.py', 'tests/test_colcon_test.py',
               'tests/test_deploy_paths.py', 'tests/test_custom_interfaces.py',
               'tests/test_grade_feedback.py')


def _group(nodeid: str) -> str:
    """The unit of work a worker gets: a test module, or a chain of lessons (nbval runs
    01-06 in order, in one workspace: 02 builds on the package 01 created; each lesson that
    stands alone is a chain of its own, run beside the others).

    The browser modules are groups of their own, each with its own lesson domains: as one
    group (taking turns in 80-88) they were ~820 s on one worker, the end of every run.
    """
    path = nodeid.split('::', 1)[0]
    if path.startswith('notebooks/'):
        return f'notebooks/{first_of_chain(Path(path).name):02d}'
    return path


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Any:
    """A failed test's report carries the last lines of every running process it was given
    as a fixture (a module's turtlesim, say): a service that did not answer shows why."""
    report = yield
    if report.failed and call.when == 'call':
        for name, value in getattr(item, 'funcargs', {}).items():
            if isinstance(value, Proc):
                report.sections.append((f'output of fixture {name!r} ({" ".join(value.cmd[-3:])})',
                                        '\n'.join(value.lines[-40:])))
    return report


@pytest.hookimpl(tryfirst=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """pytest-xdist (`./kit test -n 2`): whole groups per worker, in collection order.

    A module's fixtures (a running system) and its ROS domain stay on one worker. xdist's
    own `--dist loadgroup` cannot be used: it renames items through an attribute pytest 9
    no longer reads.
    """
    from xdist.scheduler import LoadScopeScheduling

    class ByGroup(LoadScopeScheduling):  # type: ignore[misc]
        def _split_scope(self, nodeid: str) -> str:
            return _group(nodeid)

    config.option.loadscopereorder = False
    return ByGroup(config, log)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Slow groups first; note which modules run ROS (they lease a domain when they start)."""
    _ros_modules.update(item.module.__name__ for item in items
                        if isinstance(item, pytest.Function) and item.module is not None
                        and item.get_closest_marker('no_ros') is None)
    rank = {name: i for i, name in enumerate(_SLOW_FIRST)}
    items.sort(key=lambda item: rank.get(_group(item.nodeid), len(rank)))


def _lease_domain() -> tuple[int, Any]:
    """A module domain no other running module holds, and the lock that holds it.

    Handed out round robin from a counter shared by the workers: a domain comes back only
    after every other slot has been used, long after the processes (and the DDS leases) of
    its last module are gone. More modules than slots are fine: at most one per worker
    holds one at a time.
    """
    _LEASES.mkdir(mode=0o700, exist_ok=True)
    with open(_LEASES / 'next', 'a+') as counter:
        fcntl.flock(counter, fcntl.LOCK_EX)
        counter.seek(0)
        text = counter.read().strip()
        start = int(text) if text.isdigit() else 0
        for step in range(len(_MODULE_SLOTS)):
            index = (start + step) % len(_MODULE_SLOTS)
            domain = domain_at(_MODULE_SLOTS[index])
            lock = open(_LEASES / f'{domain}.lock', 'w')  # noqa: SIM115 - held by the module
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                lock.close()
                continue
            counter.seek(0)
            counter.truncate()
            counter.write(str(index + 1))
            return domain, lock
    raise pytest.UsageError(f'tests/conftest.py: all {len(_MODULE_SLOTS)} module domains are '
                            f'leased (other pytest runs?); see {_LEASES}')


@pytest.fixture(autouse=True, scope='module')
def ros_domain(request: pytest.FixtureRequest) -> Iterator[int]:
    """A ROS_DOMAIN_ID of this module's own, so modules never hear each other (a module
    marked `no_ros` reads files only and takes no domain)."""
    if request.module.__name__ not in _ros_modules:
        assert request.node.get_closest_marker('no_ros') is not None
        yield -1
        return
    domain, lease = _lease_domain()
    old = os.environ.get('ROS_DOMAIN_ID')
    os.environ['ROS_DOMAIN_ID'] = str(domain)
    try:
        yield domain
    finally:
        if old is None:
            os.environ.pop('ROS_DOMAIN_ID', None)
        else:
            os.environ['ROS_DOMAIN_ID'] = old
        lease.close()


class Proc:
    """A running child with its merged output collected line by line in a thread."""

    def __init__(self, cmd: Sequence[str], env: dict[str, str] | None = None,
                 cwd: str | Path | None = None, stdin: int | None = None) -> None:
        self.cmd = list(cmd)
        self.popen = (spawn(self.cmd, env=env, cwd=cwd) if stdin is None
                      else spawn(self.cmd, env=env, cwd=cwd, stdin=stdin))
        self.lines: list[str] = []
        self._queue: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for raw in iter(self.popen.stdout.readline, b''):
            line = raw.decode(errors='replace').rstrip('\n')
            self.lines.append(line)
            self._queue.put(line)
        self._queue.put(None)

    def wait_for(self, pattern: str, timeout: float = 15.0) -> re.Match[str]:
        """Block until a line matches `pattern` (regex); fail with the output so far."""
        rx = re.compile(pattern)
        for line in list(self.lines):
            m = rx.search(line)
            if m:
                return m
        deadline = time.monotonic() + timeout
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                break
            try:
                line = self._queue.get(timeout=remaining)
            except queue.Empty:
                break
            if line is None:
                break
            m = rx.search(line)
            if m:
                return m
        raise AssertionError(
            f'no line matching {pattern!r} within {timeout}s from {self.cmd}:\n'
            + '\n'.join(self.lines[-40:])
        )

    @property
    def output(self) -> str:
        return '\n'.join(self.lines)

    def stop(self) -> int:
        code = stop(self.popen)
        self._reader.join(timeout=5)
        return code


REFERENCE_NODES = {
    'sensor': r'Sensor node started',
    'controller': r'Controller node started',
    'robot': r'Robot node started',
}


def run_reference_node(name: str, *ros_args: str) -> Proc:
    """`robot-lab run robot_lab <name>_node` named /<name>, as the launch file names it."""
    return Proc([str(BIN / 'robot-lab'), 'run', 'robot_lab', f'{name}_node', '--ros-args',
                 '-r', f'__node:={name}', *ros_args], env=dict(os.environ))


@contextlib.contextmanager
def reference_system(namespaces: dict[str, str] | None = None) -> Iterator[dict[str, Proc]]:
    """/sensor, /controller, /robot started and logged in (optionally in namespaces);
    always stopped on exit. For module-scoped fixtures shared by many tests."""
    started: dict[str, Proc] = {}
    try:
        for name in REFERENCE_NODES:
            ns = (namespaces or {}).get(name)
            started[name] = run_reference_node(name, *(['-r', f'__ns:={ns}'] if ns else []))
        for name, line in REFERENCE_NODES.items():
            started[name].wait_for(line, timeout=20)
        yield started
    finally:
        for proc in started.values():
            proc.stop()


@pytest.fixture
def procs() -> Iterator[list[Proc]]:
    """Collects started processes and stops every one at teardown; their last lines are
    printed then (pytest shows them only for a test that failed: what the launcher saw)."""
    started: list[Proc] = []
    yield started
    for proc in started:
        code = proc.stop()
        print(f'--- {" ".join(proc.cmd[:4])} exited {code}; its last lines:',
              *proc.lines[-30:], sep='\n')


@pytest.fixture
def start(procs: list[Proc]):  # type: ignore[no-untyped-def]
    """start(cmd...) -> Proc; `robot-lab` and `ros2` resolve to the venv's scripts."""

    def _start(*cmd: str, env: dict[str, str] | None = None, cwd: str | Path | None = None) -> Proc:
        argv = list(cmd)
        if argv and (BIN / argv[0]).exists():
            argv[0] = str(BIN / argv[0])
        full_env = dict(os.environ)
        if env:
            full_env.update(env)
        proc = Proc(argv, env=full_env, cwd=cwd)
        procs.append(proc)
        return proc

    return _start


def launched_nodes(launcher_pid: int) -> list[psutil.Process]:
    """The processes a launcher started, without the graph daemon it runs beside them
    (nor its fork server, ROBOT_LAB_FORK_SERVER=1: the nodes are its children)."""
    return [p for p in psutil.Process(launcher_pid).children(recursive=True)
            if not {'--robot-lab-graph-daemon', 'robot_lab.launch.fork_server'}
            & set(p.cmdline())]


def venv_env(**extra: str) -> dict[str, str]:
    """This process's environment with the venv's bin first on PATH (an activated venv:
    commands the test runs find `ros2`, `colcon`, `robot-lab`), plus `extra`."""
    return {**os.environ, 'PATH': f'{BIN}{os.pathsep}{os.environ["PATH"]}', **extra}


def users_profile(folder: Path) -> Path:
    """A Fast DDS profile of the user's own in `folder` (the kit then adds none): Fast
    DDS's default data path, its shared-memory ports, with the kit's log settings (its
    warnings on stderr, off a child's stdout that a test reads)."""
    profile = folder / 'users_fastdds.xml'
    profile.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">\n'
        '  <log><use_default>FALSE</use_default><consumer><class>StdoutErrConsumer</class>\n'
        '    <property><name>stderr_threshold</name><value>Log::Kind::Warning</value>'
        '</property>\n'
        '  </consumer></log>\n'
        '</dds>\n')
    return profile


def run_cli(*args: str, timeout: float = 60.0, cwd: str | Path | None = None,
            env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """Run `robot-lab ARGS` to completion and return its output (text)."""
    full_env = dict(os.environ)
    if env:
        full_env.update(env)
    return subprocess.run(
        [str(BIN / 'robot-lab'), *args], capture_output=True, text=True,
        timeout=timeout, cwd=cwd, env=full_env, check=False,
    )



def cli_ok(*args: str) -> str:
    """`robot-lab ARGS` that must succeed: its stdout (a failure shows both streams)."""
    result = run_cli(*args)
    assert result.returncode == 0, f'{args}: {result.stdout}{result.stderr}'
    return result.stdout


def cli_ok_all(*commands: Sequence[str]) -> list[str]:
    """Several cold commands at once (each mostly waits out discovery), outputs in order."""
    with ThreadPoolExecutor(len(commands)) as pool:
        return list(pool.map(lambda args: cli_ok(*args), commands))

# --- seed packages (Lab 1.3, Chapter 6) built once per run with the venv's colcon ----------


class SeedWorkspaces:
    """Built copies of the seed packages and the environment `source install/setup.bash` gives.

    `fixed`: Lab 1.3 (build type added, parameters nested) and Chapter 6, ready to launch.
    `flat`: Lab 1.3 with the build type added but its flat robot_params.yaml as written.
    """

    def __init__(self, root: Path) -> None:
        from seeds import CH6, LAB13, colcon_build, copy_seed, workspace_env

        self.fixed = root / 'fixed_ws'
        self.flat = root / 'flat_ws'
        copy_seed(LAB13, self.fixed)
        copy_seed(CH6, self.fixed)
        copy_seed(LAB13, self.flat, nest_params=False)
        colcon_build(self.fixed)
        colcon_build(self.flat)
        self.fixed_env = workspace_env(self.fixed)
        self.flat_env = workspace_env(self.flat)


@pytest.fixture(scope='session')
def seed_workspaces(tmp_path_factory: pytest.TempPathFactory) -> SeedWorkspaces:
    """The seed packages, built once per pytest run (see tests/seeds.py)."""
    return SeedWorkspaces(tmp_path_factory.mktemp('seeds'))
