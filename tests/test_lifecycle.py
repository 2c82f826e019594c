"""Lifecycle nodes: LifecycleNode with transitions driven from launch (EmitEvent(ChangeState),
OnStateTransition, autostart) and `robot-lab lifecycle nodes|get|list|set` on the same
running nodes (real rclpy lifecycle talkers, lifecycle_msgs from PyPI)."""

from __future__ import annotations

import contextlib
import queue
import signal
import time
from pathlib import Path

from conftest import Proc, run_cli

DATA = Path(__file__).resolve().parent / 'data' / 'launch' / 'events'


def wait_count(proc: Proc, text: str, count: int, timeout: float = 20.0) -> None:
    """Block until `text` has appeared in `count` output lines (each line as it arrives)."""
    deadline = time.monotonic() + timeout
    while sum(text in line for line in proc.lines) < count:
        remaining = deadline - time.monotonic()
        assert remaining > 0, f'{text!r} not seen {count} times:\n' + proc.output[-3000:]
        with contextlib.suppress(queue.Empty):
            proc._queue.get(timeout=remaining)  # the next line, or the end of the output


def test_launch_drives_transitions_and_cli_reads_and_sets_them(start, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    launch = start('robot-lab', 'launch', str(DATA / 'lifecycle.launch.py'),
                   env={'ROS_LOG_DIR': str(tmp_path)})
    # configure (EmitEvent) -> inactive -> OnStateTransition emits activate -> active
    launch.wait_for(r'\[lc_talker\]: on_configure\(\) is called', timeout=40)
    launch.wait_for(r"\[launch.user\]: node 'lc_talker' reached 'inactive', activating")
    launch.wait_for(r"\[launch.user\]: node 'lc_talker' reached 'active'")
    launch.wait_for(r"\[launch.user\]: node 'lc_auto' reached 'active'")  # autostart=True

    nodes = run_cli('lifecycle', 'nodes')
    assert nodes.stdout.splitlines() == ['/lc_auto', '/lc_talker'], nodes.stderr
    every = run_cli('lifecycle', 'get')
    assert every.stdout.splitlines() == ['/lc_auto: active [3]', '/lc_talker: active [3]']
    listed = run_cli('lifecycle', 'list', '/lc_talker')
    assert listed.stdout.splitlines() == [
        '- deactivate [4]', '\tStart: active', '\tGoal: deactivating',
        '- shutdown [7]', '\tStart: active', '\tGoal: shuttingdown']
    changed = run_cli('lifecycle', 'set', '/lc_talker', 'deactivate')
    assert changed.stdout.strip() == 'Transitioning successful', changed.stderr
    launch.wait_for(r'\[lc_talker\]: on_deactivate\(\) is called')
    # the launch's handler sees it reach 'inactive' again and activates it again, as launch's
    # OnStateTransition handlers do (they are not one-shot)
    wait_count(launch, "[launch.user]: node 'lc_talker' reached 'active'", 2)
    assert launch.output.count("node 'lc_talker' reached 'inactive', activating") == 2
    assert run_cli('lifecycle', 'get', '/lc_talker').stdout.strip() == 'active [3]'

    wrong = run_cli('lifecycle', 'set', '/lc_auto', 'bogus')
    assert wrong.returncode == 1
    assert wrong.stderr.splitlines() == [
        'Unknown transition requested, available ones are:',
        '- deactivate [4]', '- shutdown [7]']
    missing = run_cli('lifecycle', 'get', '/nope')
    assert (missing.returncode, missing.stderr.strip()) == (1, 'Node not found')

    launch.popen.send_signal(signal.SIGINT)
    assert launch.popen.wait(30) == 0
    assert launch.output.count('process has finished cleanly') == 2
