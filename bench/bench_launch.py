"""How fast `robot-lab launch robot_lab robot.launch.xml` brings the system up (issue 3).

Measured in the same run, median of RUNS runs each:
- bare trio: three bare rclpy processes started together, until each sees the other two
  (the floor any launcher is compared with);
- launch -> first `Status:` line, and its ratio to the bare trio (goal <= 1.3, issue 15;
  a real `ros2 launch` measures 1.8);
- an observer node started BEFORE the launch: time until it sees /sensor, /controller
  and /robot, from the launcher's start and from the nodes' start (first `process
  started` line) (goal <= 1 s; a real `ros2 launch` takes ~3.6 s here);
- the same with the kit's Fast DDS profile off (a user profile with no settings), to show
  what the profile buys;
- all of it on a crowded host: before the runs the bench starts an idle graph daemon, a
  kernel-like robot_lab session and --idle more bare participants (with the observer and
  the three nodes, 6+ participants in the domain; a student's host has at least that);
- total RSS of launcher + three nodes once the system runs (goal <= 230 MB);
- start-up per node: in the launch (its `process started` line -> its `... started` log
  line), and alone (exec of the kit's lib/robot_lab/<node> script -> that line, with the
  CPU seconds the node had used by then), next to a bare `python -c 'import rclpy'`.

    .venv/bin/python bench/bench_launch.py [--runs 5] [--idle 1] [--quiet] [--quick]
        [--fork-server both] [--busy 2]

--quiet: nothing runs before the launch (the issue's quiet-host figure). The launches use
the fork server (robot_lab/launch/fork_server.py) unless ROBOT_LAB_FORK_SERVER=0; with
--fork-server both, the main rows are exec'd (=0) and each run also launches with the fork
server, interleaved, so both see the same load. USS sums each process's private pages; pages the
forked nodes share only with each other are in no one's USS, so the group figure (root
only) counts the anonymous pages that only the launcher's processes map.

Node start-up, measured 2026-11-22 (2-core machine shared with other work, 5 runs each,
A/B interleaved; `OPENBLAS_NUM_THREADS=0 bench_launch.py` gives the nodes numpy's default
OpenBLAS pool again, i.e. the state before the kit's node scripts set it to 1): node alone
CPU to its "started" line 0.23-0.28 s -> 0.17-0.18 s; in the launch 0.50-0.58 s -> 0.44-0.45
s; CPU of launcher + children until the first Status 1.30 s -> 1.03 s; launch -> first
Status 0.82 s (1.55 x bare trio) -> 0.65 s (1.42 x).

Measured 2026-11-23 (idle, --runs 5, kit profile): launch -> first Status 0.83 s, 1.27x the
bare trio; observer sees all three 0.72 s after launch start, 0.59 s after the nodes' start
(profile off: 0.99 / 0.85 s); RSS launcher + 3 nodes 223 MB.

Measured 2026-11-26 (--quick --runs 5-7 --fork-server both, exec vs fork interleaved; a
host shared with five other engineers, load average 19-26 on 2 cores, so no run is quiet):
- --quiet: launch -> first Status 3.90 -> 2.21 s (bare trio 3.85 s: 1.01x -> 0.57x); CPU to
  it 1.11 -> 0.56 s; USS launcher + 3 nodes 104 -> 60 MB (fork server 8 MB of it);
  private to the group 102 -> 78 MB (3 bare nodes 84 MB).
- crowded (--idle 1): 3.30 -> 1.68 s (bare trio 2.01 s: 1.64x -> 0.84x); CPU 0.97 ->
  0.53 s; USS 104 -> 61 MB; group 103 -> 78 MB.
- crowded + 2 busy loops + a test run (load 26): 7.67 -> 8.34 s (0.94x -> 1.02x): with
  the host this oversubscribed, three exec'd nodes importing at once get three shares of
  the CPU, the one fork server one; CPU 1.03 -> 0.58 s, USS 104 -> 61 MB.

Measured 2026-11-26 evening, the fork server on by default and its nodes the launcher's
children (--quick --runs 5 --fork-server both, exec -> fork interleaved; ratio to the bare
trio, median of the per-invocation medians; load average 3-24 from other work):
- --quiet (4 invocations): 1.34x -> 0.79x; USS launcher + 3 nodes 104 -> 61 MB.
- --idle 1 (2): 0.87x -> 0.58x; USS 105 -> 61 MB.
- --quiet + two busy loops (3): 1.43x -> 1.27x; --idle 1 + two busy loops (2): 1.13x ->
  1.15x (equal within the noise); USS as above.

Measured 2026-11-28 (--quick --runs 5, fork server on, each in its own network namespace
and /dev/shm, load average 1.0-1.9 before the busy loops): --idle 1 1.21x (0.71 / 0.58 s),
--quiet 1.22x (0.56 / 0.46 s), --idle 1 + 3 busy loops 1.65x (1.34 / 0.82 s; CPU to the
first Status 0.51 s against the bare trio's 0.75: the launch is a chain of one process at a
time, and beside busy loops a chain gets one share of the CPU, three bare processes three);
USS launcher + fork server + 3 nodes 63 MB.

Measured 2026-11-28 later, the fork server started before the launch file is read (--quick):
--idle 1 0.73x (0.57 / 0.78 s, 5 runs), --quiet 1.07x (0.57 / 0.53 s); with three busy
loops 1.34x (0.94 / 0.70 s, 5 runs), then 1.65x, 1.34x, 1.26x (9 runs each). USS launcher
+ fork server + 3 nodes 62-63 MB.

Measured 2026-12-06, nodes forked with a plain os.fork as the fork server's children (exit
statuses over its socket) against clone(CLONE_PARENT) as the launcher's (--quick --runs 5,
3 A/B pairs interleaved, the old code bind-mounted over the tree in the bench's own mount
namespace; load average 12-19 from other work): ratio to the bare trio 0.94, 0.45, 0.57x
(clone) against 0.42, 0.64, 0.64x (fork); USS launcher + fork server + 3 nodes 63-64
against 62-63 MB.

Uses ROS_DOMAIN_ID (default 29) and loopback-only discovery, like everything in the kit.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import os
import queue
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import psutil
from busy import busy_loops
from memory import group_private_mb, private_mb

from robot_lab.env import ros_environment
from robot_lab.nodes import NODE_EXECUTABLES
from robot_lab.pkg.index import find_executable
from robot_lab.process import spawn, stop

BIN = Path(sys.executable).parent
NODES = ['/sensor', '/controller', '/robot']
LABEL = re.compile(r'\[(\w+)-\d+\]')  # the launcher's `[sensor_node-1]` process label

# A node that reports (wall clock) when it sees every node named on its command line.
WATCHER = r"""
import sys, time
import rclpy
from rclpy.signals import SignalHandlerOptions
rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
name, wanted = sys.argv[1], set(sys.argv[2:])
node = rclpy.create_node(name)
print('ready', time.time(), flush=True)
while True:
    names = {ns.rstrip('/') + '/' + n for n, ns in node.get_node_names_and_namespaces()}
    if wanted <= names:
        print('seen', time.time(), flush=True)
        break
    time.sleep(0.002)
try:
    time.sleep(60)
except KeyboardInterrupt:
    pass
"""

# A kernel-like participant: the kit's session (one rclpy context, its executor thread).
SESSION = r"""
import time
from robot_lab.rclpy_session import session
session().node
print('ready', time.time(), flush=True)
time.sleep(3600)
"""

# A participant that only exists (a terminal's `ros2` command, another tool).
IDLE = r"""
import sys, time
import rclpy
from rclpy.signals import SignalHandlerOptions
rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
node = rclpy.create_node(sys.argv[1])
print('ready', time.time(), flush=True)
time.sleep(3600)
"""

EMPTY_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles/></dds>
"""


class Lines:
    """A child's output lines with the wall-clock time each arrived."""

    def __init__(self, proc: subprocess.Popen[bytes]) -> None:
        self.proc = proc
        self.queue: queue.Queue[tuple[float, str] | None] = queue.Queue()
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for raw in iter(self.proc.stdout.readline, b''):
            self.queue.put((time.time(), raw.decode(errors='replace').rstrip('\n')))
        self.queue.put(None)

    def until(self, needle: str, timeout: float = 30.0) -> tuple[float, str]:
        deadline = time.monotonic() + timeout
        while True:
            item = self.queue.get(timeout=max(0.01, deadline - time.monotonic()))
            if item is None:
                raise RuntimeError(f'{self.proc.args!r} ended before printing {needle!r}')
            if needle in item[1]:
                return item


def watcher(name: str, wanted: list[str],
            env: dict[str, str]) -> tuple[subprocess.Popen[bytes], Lines]:
    proc = spawn([sys.executable, '-c', WATCHER, name, *wanted], env=env)
    return proc, Lines(proc)


def bare_trio(env: dict[str, str], cpu: list[float] | None = None,
              uss: list[float] | None = None, group: list[float] | None = None) -> float:
    """Seconds from starting three bare rclpy processes until all three saw each other
    (and, into `cpu`, the CPU seconds the three had used by then; into `uss`, their
    private memory in MB: the floor for three nodes)."""
    names = ['bare_a', 'bare_b', 'bare_c']
    began = time.time()
    started = [watcher(n, [f'/{o}' for o in names if o != n], env) for n in names]
    try:
        seen = max(float(lines.until('seen')[1].split()[1]) for _, lines in started) - began
        if cpu is not None:
            cpu.append(sum(cpu_seconds(proc.pid) for proc, _ in started))
        if uss is not None:
            uss.append(sum(private_mb(proc.pid) for proc, _ in started))
        if group is not None:
            group.append(group_private_mb(proc.pid for proc, _ in started) or 0.0)
        return seen
    finally:
        for proc, _ in started:
            stop(proc, 2, 2)


def python_start(code: str, env: dict[str, str]) -> float:
    """Seconds for `python -c code` to run and exit, in the environment nodes get."""
    began = time.perf_counter()
    subprocess.run([sys.executable, '-c', code], env=env, check=True)
    return time.perf_counter() - began


def node_alone(executable: str, env: dict[str, str]) -> tuple[float, float]:
    """Seconds from exec of the node's script to its `... started` line, and its CPU then."""
    script = find_executable('robot_lab', executable, env)
    began = time.time()
    proc = spawn([str(script), '--ros-args', '-r', f'__node:=alone_{executable}'], env=env)
    try:
        stamp = Lines(proc).until('node started')[0]
        cpu = psutil.Process(proc.pid).cpu_times()
        return stamp - began, cpu.user + cpu.system
    finally:
        stop(proc, 2, 2)


def cpu_seconds(pid: int) -> float:
    """CPU (user + system) used so far by `pid` and its descendants: steadier than wall
    time when others load the machine."""
    total = 0.0
    root = psutil.Process(pid)
    for proc in [root, *root.children(recursive=True)]:
        with contextlib.suppress(psutil.NoSuchProcess):
            times = proc.cpu_times()
            total += times.user + times.system
    return total


def launch_run(env: dict[str, str]) -> dict[str, float]:
    """One launch with an observer started first; times and the RSS of the system."""
    observer, seen = watcher('observer', NODES, env)
    seen.until('ready')
    began = time.time()
    launcher = spawn([str(BIN / 'robot-lab'), 'launch', 'robot_lab', 'robot.launch.xml'], env=env)
    out = Lines(launcher)
    try:
        spawned: dict[str, float] = {}
        up: dict[str, float] = {}
        status = status_cpu = launcher_cpu = 0.0
        while not status or len(up) < 3:  # spawns, "... started" lines, first Status:
            stamp, line = out.until('[')
            found = LABEL.search(line)
            label = found.group(1) if found else ''
            if 'process started with pid' in line:
                if not spawned:
                    times = psutil.Process(launcher.pid).cpu_times()
                    launcher_cpu = times.user + times.system
                spawned[label] = stamp
            elif 'node started' in line:
                up[label] = stamp
            elif 'Status:' in line and not status:
                status = stamp
                status_cpu = cpu_seconds(launcher.pid)
        first_start = min(spawned.values())
        all_seen = float(seen.until('seen')[1].split()[1])
        everything = [psutil.Process(launcher.pid), *psutil.Process(launcher.pid).children(True)]
        daemons = [p for p in everything if '--robot-lab-graph-daemon' in p.cmdline()]
        system = [p for p in everything if p not in daemons]  # launcher + 3 nodes
        servers = [p for p in system if 'robot_lab.launch.fork_server' in p.cmdline()]
        rss = sum(p.memory_info().rss for p in system) / 2**20
        return {
            'status': status - began,
            'seen_from_launch': all_seen - began,
            'seen_from_nodes': all_seen - first_start,
            'seen_from_last_up': all_seen - max(up.values()),
            'rss': rss,
            'launcher_rss': system[0].memory_info().rss / 2**20,
            'uss': sum(private_mb(p.pid) for p in system),
            'launcher_uss': private_mb(launcher.pid),
            'fork_server_uss': sum(private_mb(p.pid) for p in servers),
            'group': group_private_mb(p.pid for p in system) or 0.0,
            'daemon_uss': sum(private_mb(p.pid) for p in daemons),
            'daemon_rss': sum(p.memory_info().rss for p in daemons) / 2**20,
            'launcher_to_first_spawn': first_start - began,
            'status_cpu': status_cpu,
            'launcher_cpu_to_spawn': launcher_cpu,
            'status_after_pair_up': status - max(up['controller_node'], up['robot_node']),
            **{f'up_{name}': up[name] - spawned[name] for name in NODE_EXECUTABLES},
        }
    finally:
        stop(launcher, 5, 5)
        stop(observer, 2, 2)


@contextlib.contextmanager
def crowd(env: dict[str, str], idle: int) -> Iterator[int]:
    """An idle graph daemon, a kernel-like session and `idle` bare participants, all up
    (and discovered by the daemon) before the block; yields how many participants."""
    from robot_lab.graph import daemon

    if idle < 0:  # a quiet host: nothing else running
        yield 0
        return
    procs = [spawn([sys.executable, '-c', SESSION], env=env)]
    procs += [spawn([sys.executable, '-c', IDLE, f'idle_{n}'], env=env) for n in range(idle)]
    try:
        for proc in procs:
            Lines(proc).until('ready', 60)
        if not daemon.is_running(env):
            procs.append(daemon.start(detached=False, env=env))
            if not daemon.wait_until_running(60, env, procs[-1]):
                raise RuntimeError('the graph daemon did not start')
        yield len(procs)
    finally:
        for proc in procs:
            stop(proc, 2, 2)


def median(runs: list[dict[str, float]], key: str) -> float:
    return statistics.median(r[key] for r in runs)


def memory_rows(runs: list[dict[str, float]], bare_uss: list[float],
                bare_group: list[float]) -> list[tuple[str, str, str]]:
    """Private memory of launcher (+ fork server) + 3 nodes, each next to its floor."""
    return [
        ('private (USS) launcher (+ fork server) + 3 nodes', f'{median(runs, "uss"):.0f} MB',
         f'<= 80 MB (floor: 3 bare rclpy nodes {statistics.median(bare_uss):.0f} MB)'),
        ('  of which the launcher', f'{median(runs, "launcher_uss"):.0f} MB', ''),
        ('  of which a fork server', f'{median(runs, "fork_server_uss"):.0f} MB', ''),
        ('private to the group (pages shared only among them counted)',
         f'{median(runs, "group"):.0f} MB',
         f'(floor: 3 bare rclpy nodes {statistics.median(bare_group):.0f} MB; root only)'),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=5)
    parser.add_argument('--idle', type=int, default=1,
                        help='bare participants started besides the daemon and a session')
    parser.add_argument('--busy', type=int, default=0,
                        help='busy loops (`while True: pass`) running beside the runs')
    parser.add_argument('--quiet', action='store_true',
                        help='a quiet host: no daemon, session or idle participants first')
    parser.add_argument('--fork-server', choices=('env', 'both'), default='env',
                        help='both: exec (ROBOT_LAB_FORK_SERVER=0) and fork, interleaved')
    parser.add_argument('--quick', action='store_true',
                        help='only the launch and the bare trio, with the kit profile')
    parser.add_argument('--compare-source', action='store_true',
                        help='also measure (interleaved) with every module compiled from source')
    args = parser.parse_args()
    env = ros_environment({'ROS_DOMAIN_ID': os.environ.get('ROS_DOMAIN_ID', '29')})
    with tempfile.TemporaryDirectory() as tmp:
        env['ROS_LOG_DIR'] = tmp
        # Like an installed kit (pip writes .pyc files): cached bytecode, kept out of the
        # work tree. PYTHONDONTWRITEBYTECODE=1 (set in some sandboxes) otherwise makes the
        # launcher and every node compile the kit's modules at each start.
        env_source = dict(env, PYTHONDONTWRITEBYTECODE='1')
        env_source.pop('PYTHONPYCACHEPREFIX', None)
        env.pop('PYTHONDONTWRITEBYTECODE', None)
        env['PYTHONPYCACHEPREFIX'] = str(Path(tmp) / 'pycache')
        bare_src: list[float] = []
        launched_src: list[dict[str, float]] = []
        profile = Path(tmp) / 'empty_profile.xml'
        profile.write_text(EMPTY_PROFILE)
        env_off = dict(env, FASTRTPS_DEFAULT_PROFILES_FILE=str(profile))
        bare, launched, bare_off, launched_off = [], [], [], []
        bare_cpu: list[float] = []
        bare_uss: list[float] = []
        bare_group: list[float] = []
        forked: list[dict[str, float]] = []
        if args.fork_server == 'both':
            env['ROBOT_LAB_FORK_SERVER'] = '0'
        env_fork = dict(env, ROBOT_LAB_FORK_SERVER='1')
        alone: dict[str, list[tuple[float, float]]] = {n: [] for n in NODE_EXECUTABLES}
        interpreter: dict[str, list[float]] = {'pass': [], 'import rclpy': []}
        with contextlib.ExitStack() as loops:
            loops.enter_context(busy_loops(args.busy))
            crowded = loops.enter_context(crowd(env, -1 if args.quiet else args.idle))
            launch_run(env)  # writes the bytecode cache; not counted
            load = os.getloadavg()[0]
            for _ in range(args.runs):
                if args.compare_source:
                    bare_src.append(bare_trio(env_source))
                    launched_src.append(launch_run(env_source))
                bare.append(bare_trio(env, bare_cpu, bare_uss, bare_group))
                launched.append(launch_run(env))
                if args.fork_server == 'both':
                    forked.append(launch_run(env_fork))
                if args.quick:
                    continue
                bare_off.append(bare_trio(env_off))
                launched_off.append(launch_run(env_off))
                for name in NODE_EXECUTABLES:
                    alone[name].append(node_alone(name, env))
                for code in interpreter:
                    interpreter[code].append(python_start(code, env))
            load = (load + os.getloadavg()[0]) / 2

    trio = statistics.median(bare)
    rows = [
        ('bare trio: three rclpy processes see each other', f'{trio:.2f} s', ''),
        ('launch -> first Status: line', f'{median(launched, "status"):.2f} s', ''),
        ('  ratio to bare trio', f'{median(launched, "status") / trio:.2f}', '<= 1.3'),
        ('  CPU used by launcher + children until then',
         f'{median(launched, "status_cpu"):.2f} s',
         f'(bare trio {statistics.median(bare_cpu):.2f} s)'),
        ('  CPU used by the launcher before its first spawn',
         f'{median(launched, "launcher_cpu_to_spawn"):.2f} s', ''),
        ('observer (started first) sees all 3 nodes, from launch',
         f'{median(launched, "seen_from_launch"):.2f} s', ''),
        ("observer sees all 3 nodes, from the nodes' start",
         f'{median(launched, "seen_from_nodes"):.2f} s', '<= 1 s'),
        ('observer sees all 3 nodes, after the last node is up',
         f'{median(launched, "seen_from_last_up"):.2f} s', ''),
        ('RSS launcher + 3 nodes', f'{median(launched, "rss"):.0f} MB', '<= 230 MB'),
        ('  of which the launcher', f'{median(launched, "launcher_rss"):.0f} MB', ''),
        *memory_rows(launched, bare_uss, bare_group),
        ('  graph daemon beside them, private (RSS), not counted above',
         f'{median(launched, "daemon_uss"):.0f} MB ({median(launched, "daemon_rss"):.0f} MB)', ''),
        ('launch -> first process started', f'{median(launched, "launcher_to_first_spawn"):.2f} s',
         ''),
        ('first Status: after controller and robot are both up',
         f'{median(launched, "status_after_pair_up"):.3f} s', ''),
        *[(f'{name}: process started -> "started" line, in launch',
           f'{median(launched, "up_" + name):.2f} s', '') for name in NODE_EXECUTABLES],
    ]
    if forked:
        rows += [
            ('-- fork server (ROBOT_LAB_FORK_SERVER=1), interleaved with the above --', '', ''),
            ('launch -> first Status: line', f'{median(forked, "status"):.2f} s', ''),
            ('  ratio to bare trio', f'{median(forked, "status") / trio:.2f}', '<= 1.3'),
            ('  CPU used by launcher + children until then',
             f'{median(forked, "status_cpu"):.2f} s', ''),
            ('observer (started first) sees all 3 nodes, from launch',
             f'{median(forked, "seen_from_launch"):.2f} s', ''),
            ('launch -> first process started (forked once the server is ready)',
             f'{median(forked, "launcher_to_first_spawn"):.2f} s', ''),
            ('RSS launcher + fork server + 3 nodes', f'{median(forked, "rss"):.0f} MB', ''),
            *memory_rows(forked, bare_uss, bare_group),
        ]
    if launched_src:
        trio_src = statistics.median(bare_src)
        rows += [
            ('-- every module compiled from source (PYTHONDONTWRITEBYTECODE=1) --', '', ''),
            ('bare trio', f'{trio_src:.2f} s', ''),
            ('launch -> first Status: line', f'{median(launched_src, "status"):.2f} s', ''),
            ('  ratio to bare trio', f'{median(launched_src, "status") / trio_src:.2f}', ''),
            ('  CPU used by launcher + children until then',
             f'{median(launched_src, "status_cpu"):.2f} s', ''),
            ("observer sees all 3 nodes, from the nodes' start",
             f'{median(launched_src, "seen_from_nodes"):.2f} s', ''),
        ]
    if not args.quick:
        rows += [
            *[(f'{name} alone: exec -> "started" line (CPU s)',
               f'{statistics.median(t for t, _ in alone[name]):.3f} s',
               f'({statistics.median(c for _, c in alone[name]):.3f})')
              for name in NODE_EXECUTABLES],
            *[(f"python -c '{code}' (kit env)", f'{statistics.median(times):.3f} s', '')
              for code, times in interpreter.items()],
            ('-- kit Fast DDS profile off --', '', ''),
            ('bare trio', f'{statistics.median(bare_off):.2f} s', ''),
            ('launch -> first Status: line', f'{median(launched_off, "status"):.2f} s', ''),
            ('observer sees all 3 nodes, from launch',
             f'{median(launched_off, "seen_from_launch"):.2f} s', ''),
            ("observer sees all 3 nodes, from the nodes' start",
             f'{median(launched_off, "seen_from_nodes"):.2f} s', ''),
            ('observer sees all 3 nodes, after the last node is up',
             f'{median(launched_off, "seen_from_last_up"):.2f} s', ''),
        ]
    width = max(len(r[0]) for r in rows)
    print(f'robot-lab launch robot_lab robot.launch.xml, median of {args.runs} runs '
          f'(ROS_DOMAIN_ID={env["ROS_DOMAIN_ID"]}; {crowded} participants already up + '
          f'observer + 3 nodes; {args.busy} busy loops; load average {load:.1f} on '
          f'{os.cpu_count()} cores)')
    for name, value, goal in rows:
        print(f'{name:<{width}}  {value:>8}  {goal}')
    print('all runs (status / seen from launch / from nodes / after last up, s; RSS MB):')
    for label, runs in (('profile on ', launched), ('fork server', forked),
                        ('profile off', launched_off),
                        ('from source', launched_src)):
        if not runs:
            continue
        print(f'  {label}: ' + ', '.join(
            f'{r["status"]:.2f}/{r["seen_from_launch"]:.2f}/{r["seen_from_nodes"]:.2f}/'
            f'{r["seen_from_last_up"]:.2f}/{r["rss"]:.0f}' for r in runs))
    print('bare trio runs (on/off): ' + ', '.join(
        f'{a:.2f}/{b:.2f}' for a, b in itertools.zip_longest(bare, bare_off, fillvalue=0.0)))


if __name__ == '__main__':
    main()
