"""Fresh CLI processes on a loaded host: are their graph lists complete, and how fast?

A class hub has more students than cores, and every `ros2 node list` typed there is a new
process (a new DDS participant when no daemon answers). This starts the seed system
(`robot-lab launch robot_lab robot.launch.xml`), an action server (`fibonacci_node`) and
a service server (`switch_node`), then three busy loops, and runs ROUNDS rounds of the four
list verbs, each a fresh process:

    robot-lab node list | topic list | service list | action list -t

in two modes: `warm` (the launch's graph daemon answers, as on a hub) and `cold`
(`ROBOT_LAB_NO_DAEMON=1`: every command is its own participant). An answer is complete
when it equals what a session warm for several seconds lists. Prints complete/total
(goal 100 %) and the median seconds per command (goal <= 1.0 s) per mode and verb.

    .venv/bin/python bench/bench_cli_load.py [--rounds 25] [--busy 3] [--modes warm,cold]

Uses ROS_DOMAIN_ID 58 unless set (keep benchmarks off other people's domains).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from busy import busy_loops

os.environ.setdefault('ROS_DOMAIN_ID', '58')

import robot_lab
from robot_lab.env import ros_environment
from robot_lab.process import spawn, stop

BIN = Path(sys.executable).parent
CLI = str(BIN / 'robot-lab')
VERBS = {
    'node list': ['node', 'list'],
    'topic list': ['topic', 'list'],
    'service list': ['service', 'list'],
    'action list -t': ['action', 'list', '-t'],
}
NODES = ['/controller', '/fibonacci_action_server', '/robot', '/sensor', '/switch']


def start_system() -> list[subprocess.Popen[bytes]]:
    quiet = {'stdout': subprocess.DEVNULL, 'stderr': subprocess.DEVNULL}
    env = ros_environment()
    return [spawn([CLI, 'launch', 'robot_lab', 'robot.launch.xml'], env=env, **quiet),
            spawn([CLI, 'run', 'robot_lab', 'fibonacci_node'], env=env, **quiet),
            spawn([CLI, 'run', 'robot_lab', 'switch_node'], env=env, **quiet)]


def expected_answers() -> dict[str, str]:
    """What each verb prints, from this process's session once it has seen every node and
    a few seconds of quiet (a reference, not timed)."""
    robot_lab.wait_for_nodes(NODES, timeout=60)
    from robot_lab.graph.actions import action_list
    from robot_lab.graph.services import service_list_typed
    from robot_lab.graph.topics import topic_list

    def answers() -> dict[str, str]:
        return {
            'node list': ''.join(f'{n}\n' for n in robot_lab.node_list()),
            'topic list': ''.join(f'{n}\n' for n, _ in topic_list()),
            'service list': ''.join(f'{n}\n' for n, _ in service_list_typed()),
            'action list -t': ''.join(f'{n} [{", ".join(t)}]\n' for n, t in action_list()),
        }

    previous = answers()
    while True:  # until two answers 2 s apart agree: the reference graph is settled
        time.sleep(2.0)  # the interval of the stability check, not a synchronisation
        current = answers()
        if current == previous and '/fibonacci' in current['action list -t']:
            return current
        previous = current


def run_verb(args: list[str], env: dict[str, str]) -> tuple[float, str]:
    start = time.monotonic()
    out = subprocess.run([CLI, *args], capture_output=True, text=True, check=False,
                         env=env, timeout=120).stdout
    # Fast DDS logs to stdout when a shared-memory port is taken; not the verb's output.
    out = ''.join(line for line in out.splitlines(keepends=True)
                  if 'RTPS_TRANSPORT_SHM' not in line)
    return time.monotonic() - start, out


def measure(mode: str, rounds: int, expected: dict[str, str]) -> list[tuple[str, str]]:
    env = ros_environment({'ROBOT_LAB_NO_DAEMON': '1'} if mode == 'cold' else None)
    # A student's Python keeps its bytecode cache; a shell that turned that off (as some
    # sandboxes do) would time the compiler instead of the command.
    env.pop('PYTHONDONTWRITEBYTECODE', None)
    times: dict[str, list[float]] = {verb: [] for verb in VERBS}
    complete: dict[str, int] = dict.fromkeys(VERBS, 0)
    misses: list[str] = []
    for index in range(rounds):
        for verb, args in VERBS.items():
            took, out = run_verb(args, env)
            times[verb].append(took)
            if out == expected[verb]:
                complete[verb] += 1
            else:
                misses.append(f'  round {index + 1} {verb}: got {out!r}')
        print(f'{mode}: round {index + 1}/{rounds}', file=sys.stderr, flush=True)
    rows = []
    for verb in VERBS:
        rows.append((f'{mode:<4}  {verb}', f'{complete[verb]}/{rounds} complete, '
                     f'median {statistics.median(times[verb]):.2f} s '
                     f'(max {max(times[verb]):.2f})'))
    every = [t for samples in times.values() for t in samples]
    total = sum(complete.values())
    rows.append((f'{mode:<4}  all four', f'{total}/{rounds * len(VERBS)} complete '
                 f'({100 * total / (rounds * len(VERBS)):.0f} %), '
                 f'median {statistics.median(every):.2f} s per command'))
    for miss in misses[:10]:
        print(miss, file=sys.stderr)
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--rounds', type=int, default=25)
    parser.add_argument('--busy', type=int, default=3, help='busy loops beside the system')
    parser.add_argument('--modes', default='warm,cold')
    args = parser.parse_args()
    system = start_system()
    rows: list[tuple[str, str]] = []
    try:
        expected = expected_answers()
        with busy_loops(args.busy):
            for mode in args.modes.split(','):
                rows += measure(mode, args.rounds, expected)
    finally:
        for proc in system:
            stop(proc)
    load = os.getloadavg()[0]
    width = max(len(name) for name, _ in rows)
    print(f'{args.busy} busy loops, load average {load:.1f} at the end '
          f'({os.cpu_count()} cores)')
    print(f'{"mode  verb":<{width}}  result (fresh process per command)')
    print(f'{"-" * width}  {"-" * 40}')
    for name, value in rows:
        print(f'{name:<{width}}  {value}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
