"""A killed participant's shared-memory segment is swept; a live one's is never touched."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from robot_lab.shared_memory import sweep_dead_segments

# A node that publishes once (Fast DDS maps its segment when it has data to send), says so,
# and stays.
NODE = """
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('shm_probe')
node.create_publisher(String, 'shm_probe', 10).publish(String(data='x'))
print('up', flush=True)
rclpy.spin(node)
"""


def _own_segments(pid: int) -> set[Path]:
    """The Fast DDS segments process `pid` made: of those it maps (a peer's too, once it has
    heard from one), the ones whose lock file it holds (/proc/locks: pid, then dev:inode)."""
    held = set()
    for line in Path('/proc/locks').read_text().splitlines():
        fields = line.split()
        fields = fields[2:] if fields[1] == '->' else fields[1:]  # '->': waiting for it
        if len(fields) > 4 and fields[3] == str(pid):
            held.add(int(fields[4].rsplit(':', 1)[1]))
    found = set()
    for name in re.findall(r'(/dev/shm/fastrtps_[0-9a-f]{16})$',
                           Path(f'/proc/{pid}/maps').read_text(), re.M):
        with contextlib.suppress(FileNotFoundError):
            if os.stat(f'{name}_el').st_ino in held:
                found.add(Path(name))
    return found


def _start() -> tuple[subprocess.Popen[str], set[Path]]:
    proc = subprocess.Popen([sys.executable, '-c', NODE], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline() == 'up\n'
    deadline = time.monotonic() + 10
    while not (segments := _own_segments(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.05)  # polling /proc: the mapping has no event to wait on
    assert segments, 'the node mapped no shared-memory segment'
    return proc, segments


def test_a_killed_nodes_segment_is_swept_and_a_live_ones_kept() -> None:
    killed, dead = _start()
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    live, kept = _start()
    try:
        assert dead.isdisjoint(kept)
        assert all(p.exists() and Path(f'{p}_el').exists() for p in dead)  # what -9 leaves
        sweep_dead_segments()  # too young to judge (a lock file is made, then locked)
        assert all(p.exists() for p in dead)
        # Aged by hand, not by waiting; a sweep with no minimum age could take another
        # test's participant between making its lock file and locking it.
        hour_ago = time.time() - 3600
        for path in dead:
            os.utime(f'{path}_el', (hour_ago, hour_ago))
        swept = sweep_dead_segments()
        assert swept.segments >= len(dead) and swept.bytes > 0
        assert not any(p.exists() or Path(f'{p}_el').exists() for p in dead)
        assert all(p.exists() and Path(f'{p}_el').exists() for p in kept)
        assert live.poll() is None
    finally:
        live.send_signal(signal.SIGINT)
        live.wait(30)
    assert not any(p.exists() for p in kept)  # a clean exit removes its own


def _dead_segment(age: float = 3600) -> Path:
    """A segment as a killed participant leaves it: the file, and its lock file unlocked."""
    segment = Path(f'/dev/shm/fastrtps_{os.urandom(8).hex()}')
    segment.write_bytes(b'\0' * 4096)
    lock = Path(f'{segment}_el')
    lock.touch()
    then = time.time() - age
    os.utime(lock, (then, then))
    return segment


def test_a_launch_that_ends_and_a_lessons_setup_sweep(tmp_path: Path) -> None:
    launch = tmp_path / 'one.launch.xml'
    launch.write_text('<launch><executable cmd="true" output="screen"/></launch>\n')
    first = _dead_segment()
    done = subprocess.run([str(Path(sys.executable).parent / 'robot-lab'), 'launch', str(launch)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert not first.exists() and not Path(f'{first}_el').exists()
    second = _dead_segment()
    young = _dead_segment(age=0)
    setup = "from robot_lab.grading.course import setup; setup('01_create_package')"
    done = subprocess.run([sys.executable, '-c', setup], capture_output=True, text=True,
                          timeout=60, env={**os.environ, 'ROBOT_LAB_WORKSPACE': str(tmp_path)})
    assert done.returncode == 0, done.stderr
    assert not second.exists()
    assert young.exists()  # made an instant ago: perhaps a participant about to lock it
    young.unlink()
    Path(f'{young}_el').unlink()
