"""The kit under load (issue 15.6): a fleet of robots in one domain, a class of kernels.

Fleet: `robot-lab launch robot_lab robot_fleet.launch.xml` (10 robots, 30 nodes) with an
observer session started first. Prints
- launch -> every node up (its `... started` line), and -> the observer sees all 30;
- the observer sees all 30 nodes, counted from the last node's `started` line (goal: 2 s);
- `robot-lab node list` typed when the last node is up: how many of the 30 it lists, and
  how long after the last `started` line the first complete list was printed;
- each sensor's rate over --window seconds as the observer received it, against the
  parameter file's sensor_rate (goal: all within 1 %);
- memory: RSS of launcher + nodes (+ daemon), and per node.

Class: --kernels simulated student kernels, each a Python process with the kit's session
in a domain of its own (leased from the host registry, robot_lab/domain.py, like the
grader's jobs), which launches the reference system (robot_lab.launch) as a notebook
does. Once all are up, each is asked --rounds times for `param_get('/sensor',
'sensor_rate')` in turn; prints the answer times (median, max, per kernel worst), how
many kernels answered every request within --answer-within seconds, and the memory.

    .venv/bin/python bench/bench_load.py [--kernels 20] [--skip-fleet]
        [--skip-class] [--window 20] [--rounds 5]

Measured 2026-11-26, --skip-fleet --kernels 3 --rounds 3 (load average ~8 on 2 cores):
USS per student 143 MB exec'd -> 90 MB forked (floor: a bare session +
3 bare rclpy nodes 114 MB); private to each student's processes 141 -> 118 MB (floor 112).
Again, nodes forked as the launcher's children (the default; 3 runs each, interleaved,
idle load 8-9 and with two busy loops): USS per student 148 -> 89-90 MB; RSS 290 -> 337 MB
(pages shared by the forked nodes count in each one's RSS).

Uses ROS_DOMAIN_ID (default 29) for the fleet; loopback-only discovery, like the kit.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from tempfile import TemporaryDirectory
from typing import IO

import psutil
import yaml
from bench_launch import IDLE, SESSION, Lines
from memory import group_private_mb, tree_memory

from robot_lab.env import ros_environment
from robot_lab.launch.fork_client import enabled as fork_server_enabled
from robot_lab.process import spawn, stop

BIN = Path(sys.executable).parent
ROBOTS = 10  # in launch/robot_fleet.launch.xml
CONFIG = Path(__file__).resolve().parents[1] / 'config' / 'robot_params.yaml'

# Started before the fleet: reports when it sees every node, and the sensors' messages.
OBSERVER = r"""
import json, sys, threading, time
from robot_lab.rclpy_session import session
from std_msgs.msg import Float32
robots = int(sys.argv[1])
node = session().node
wanted = {f'/robot{i}/{n}' for i in range(1, robots + 1) for n in ('sensor', 'controller', 'robot')}
lock = threading.Lock()
arrivals = {f'/robot{i}/sensor/temperature': [] for i in range(1, robots + 1)}
def counter(topic):
    def count(msg):
        with lock:
            arrivals[topic].append(time.monotonic())
    return count
subs = [node.create_subscription(Float32, t, counter(t), 50) for t in arrivals]
print('ready', time.time(), flush=True)
while True:
    names = {ns.rstrip('/') + '/' + n for n, ns in node.get_node_names_and_namespaces()}
    if wanted <= names:
        print('seen', time.time(), flush=True)
        break
    time.sleep(0.005)
import os
for line in os.fdopen(int(sys.argv[-1])):
    with lock:
        if line.strip() == 'mark':
            for times in arrivals.values():
                times.clear()
            print('marked', flush=True)
        elif line.strip() == 'report':
            print('report', json.dumps(arrivals), flush=True)
"""

# A simulated student kernel: a lesson's set-up (with the graph daemon it keeps for the
# notebook's commands), the kit's session, the reference system launched as a notebook
# does, then one `param_get` per line on stdin.
KERNEL = r"""
import sys, time
import robot_lab
from robot_lab.grading import setup
setup('04_parameters')
handle = robot_lab.launch('robot_lab', 'robot.launch.xml')
robot_lab.wait_for_nodes(['/sensor', '/controller', '/robot'], timeout=600)
print('up', time.time(), flush=True)
import os
for line in os.fdopen(int(sys.argv[-1])):
    began = time.perf_counter()
    try:
        value = robot_lab.param_get('/sensor', 'sensor_rate')
    except Exception as exc:
        value = repr(exc).replace(' ', '_')
    print('answer', time.perf_counter() - began, value, flush=True)
handle.shutdown()
"""


def spawn_fed(code: str, args: list[str], env: dict[str, str]) -> tuple[
        subprocess.Popen[bytes], IO[bytes]]:
    """`python -c code args... FD`: the child reads its requests from FD, we write them."""
    read_end, write_end = os.pipe()
    try:
        proc = spawn([sys.executable, '-c', code, *args, str(read_end)], env=env,
                     pass_fds=[read_end])
    finally:
        os.close(read_end)
    return proc, os.fdopen(write_end, 'wb', buffering=0)


def node_list(env: dict[str, str]) -> list[str]:
    result = subprocess.run([str(BIN / 'robot-lab'), 'node', 'list'], env=env,
                            capture_output=True, text=True, timeout=60)
    return [line for line in result.stdout.splitlines() if line.startswith('/')]


def fleet(env: dict[str, str], robots: int, window: float) -> None:
    nominal = float(yaml.safe_load(CONFIG.read_text())['/**']['ros__parameters']['sensor_rate'])
    wanted = {f'/robot{i}/{n}' for i in range(1, robots + 1)
              for n in ('sensor', 'controller', 'robot')}
    observer, ask = spawn_fed(OBSERVER, [str(robots)], env)
    seen = Lines(observer)
    seen.until('ready', 120)
    began = time.time()
    launcher = spawn([str(BIN / 'robot-lab'), 'launch', 'robot_lab', 'robot_fleet.launch.xml'],
                     env=env)
    out = Lines(launcher)
    try:
        up: list[float] = []
        while len(up) < len(wanted):
            stamp, line = out.until('started', 600)
            if 'node started' in line:
                up.append(stamp)
        last_up = max(up)
        typed = time.time()
        listed = node_list(env)
        answered = time.time() - typed
        first_complete = time.time() - last_up if wanted <= set(listed) else None
        first_count = len(wanted & set(listed))
        while first_complete is None and time.time() - last_up < 60:
            if wanted <= set(node_list(env)):
                first_complete = time.time() - last_up
        all_seen = float(seen.until('seen', 600)[1].split()[1])
        ask.write(b'mark\n')
        seen.until('marked', 60)
        time.sleep(window)  # the measuring window, not a wait for an event
        ask.write(b'report\n')
        arrivals: dict[str, list[float]] = json.loads(seen.until('report', 60)[1].split(' ', 1)[1])
        rates = {t: (len(a) - 1) / (a[-1] - a[0]) for t, a in arrivals.items() if len(a) > 1}
        total, private, rows = tree_memory(launcher.pid)
        node_mb = [mb for cmd, mb, _ in rows if '_node' in cmd]
        node_uss = [uss for cmd, _, uss in rows if '_node' in cmd]
    finally:
        stop(launcher, 10, 10)
        ask.close()
        stop(observer, 5, 5)
    deviations = sorted(abs(r - nominal) / nominal * 100 for r in rates.values())
    print(f'fleet: {robots} robots, {len(wanted)} nodes in ROS_DOMAIN_ID={env["ROS_DOMAIN_ID"]} '
          f'(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)')
    print(f'  launch -> all nodes up ("started" lines)           {last_up - began:7.2f} s')
    print(f'  launch -> observer sees all {len(wanted)} nodes               '
          f'{all_seen - began:7.2f} s')
    print(f'  observer sees all, after the last node is up       {all_seen - last_up:7.2f} s'
          '   goal <= 2 s')
    done = 'never' if first_complete is None else f'{first_complete:.2f} s'
    print(f'  `node list` typed when the last node is up: {first_count}/{len(wanted)} listed '
          f'(answered in {answered:.2f} s); a complete list after {done}')
    print(f'  sensor rates over {window:g} s (nominal {nominal:g} Hz): '
          + ', '.join(f'{rates[t]:.3f}' for t in sorted(rates)))
    print(f'  deviation from nominal: max {max(deviations):.2f} %, median '
          f'{statistics.median(deviations):.2f} %   goal <= 1 %'
          f'  ({len(rates)}/{robots} sensors heard)')
    print(f'  RSS launcher + nodes + daemon: {total:.0f} MB; per node median '
          f'{statistics.median(node_mb):.0f} MB, max {max(node_mb):.0f} MB')
    print(f'  private (USS) launcher + nodes + daemon: {private:.0f} MB; per node median '
          f'{statistics.median(node_uss):.0f} MB')


def student_floor(env: dict[str, str]) -> tuple[float, float]:
    """USS (summed, and private to the group) of a bare student: a kernel-like session and
    three bare rclpy nodes, nothing of the kit's launch: what one student costs at least."""
    procs = [spawn([sys.executable, '-c', SESSION], env=env)]
    procs += [spawn([sys.executable, '-c', IDLE, f'bare_{n}'], env=env) for n in range(3)]
    try:
        for proc in procs:
            Lines(proc).until('ready', 300)
        pids = [p.pid for p in procs]
        return sum(tree_memory(pid)[1] for pid in pids), group_private_mb(pids) or 0.0
    finally:
        for proc in procs:
            stop(proc, 5, 5)


def kernels(base_env: dict[str, str], count: int, rounds: int, within: float) -> None:
    from robot_lab.domain import lease_domains

    with lease_domains(count, 'bench_load kernels') as domains:
        began = time.time()
        fed = [spawn_fed(KERNEL, [], dict(base_env, ROS_DOMAIN_ID=str(d))) for d in domains]
        procs = [proc for proc, _ in fed]
        asks = [ask for _, ask in fed]
        lines = [Lines(p) for p in procs]
        try:
            ups = [float(out.until('up', 900)[1].split()[1]) for out in lines]
            answers: list[list[float]] = [[] for _ in procs]
            wrong = 0
            for _ in range(rounds):
                for ask, out, mine in zip(asks, lines, answers, strict=True):
                    ask.write(b'get\n')
                    _, seconds, value = out.until('answer', 120)[1].split()
                    mine.append(float(seconds))
                    wrong += value != '10'
            measured = [tree_memory(p.pid) for p in procs]
            total = sum(m[0] for m in measured)
            private = sum(m[1] for m in measured)
            own = [group_private_mb(
                [p.pid, *(c.pid for c in psutil.Process(p.pid).children(recursive=True))])
                or 0.0 for p in procs]
        finally:
            for ask in asks:
                with contextlib.suppress(OSError):
                    ask.close()  # the kernel shuts its launch down and exits
            for proc in procs:
                stop(proc, 20, 10)
        floor, floor_own = student_floor(dict(base_env, ROS_DOMAIN_ID=str(min(domains))))
    flat = [s for mine in answers for s in mine]
    worst = [max(mine) for mine in answers]
    print(f'class: {count} simulated kernels, each its own domain from the registry '
          f'({",".join(map(str, sorted(domains)))}) with the reference system '
          f'(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)')
    print(f'  all kernels up (3 nodes each seen)                 {max(ups) - began:7.2f} s')
    print(f'  param_get /sensor sensor_rate, {rounds} rounds: median '
          f'{statistics.median(flat):.3f} s, max {max(flat):.3f} s; per-kernel worst: '
          f'median {statistics.median(worst):.3f} s')
    print(f'  kernels that answered every request within {within:g} s: '
          f'{sum(w <= within for w in worst)}/{count}; wrong answers: {wrong}')
    print(f'  RSS of all kernels + their nodes and daemons: {total:.0f} MB '
          f'({total / count:.0f} MB per student)')
    print(f'  private (USS) of the same: {private:.0f} MB ({private / count:.0f} MB per '
          f'student, what one more student adds)   goal <= 200 MB (floor: a bare session '
          f'+ 3 bare rclpy nodes {floor:.0f} MB)')
    print("  private to each student's processes (pages shared only among them counted, "
          f'root only): median {statistics.median(own):.0f} MB   (floor {floor_own:.0f} MB)')
    how = 'forked by' if fork_server_enabled() else 'not by (ROBOT_LAB_FORK_SERVER=0)'
    print(f'  nodes started {how} a fork server')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--kernels', type=int, default=20)
    parser.add_argument('--window', type=float, default=20.0,
                        help='seconds over which the sensor rates are measured')
    parser.add_argument('--rounds', type=int, default=5)
    parser.add_argument('--answer-within', type=float, default=2.0)
    parser.add_argument('--skip-fleet', action='store_true')
    parser.add_argument('--skip-class', action='store_true')
    args = parser.parse_args()
    env = ros_environment({'ROS_DOMAIN_ID': os.environ.get('ROS_DOMAIN_ID', '29')})
    with TemporaryDirectory() as tmp:
        env['ROS_LOG_DIR'] = tmp
        env.pop('PYTHONDONTWRITEBYTECODE', None)  # as installed: see bench_launch.py
        env['PYTHONPYCACHEPREFIX'] = str(Path(tmp) / 'pycache')
        if not args.skip_fleet:
            fleet(env, ROBOTS, args.window)
        if not args.skip_class:
            class_env = dict(env)
            del class_env['ROS_DOMAIN_ID']
            kernels(class_env, args.kernels, args.rounds, args.answer_within)


if __name__ == '__main__':
    main()
