"""A grading job's processes are out of reach of signals sent to the grader's process group
(issue 22: a graded student's sensor died of rclpy's ExternalShutdownException, a SIGINT,
before it was observed). Jupyter interrupts a kernel with killpg(SIGINT) on the kernel's
group, a terminal's Ctrl-C reaches its whole foreground group: a job in the grader's group
got those too, and with them every node the student's launch file had started."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

# The job: the first thing every job does (`enter`), then a SIGINT handler that notes the
# signal, then 'ready'. Once the test has signalled the grader's group it creates `sent`;
# a pending signal is delivered before the read that sees `sent` returns, so the job's
# answer is final (no observation window).
JOB = """
import os, signal, sys, time
from pathlib import Path
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import enter
enter(Limits(), bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')))
got = []
signal.signal(signal.SIGINT, lambda *_: got.append('SIGINT'))
here = Path(sys.argv[-1])
(here / 'ready').write_text(str(os.getpgrp()))
while not (here / 'sent').exists():
    time.sleep(0.01)
(here / 'answer').write_text(','.join(got) or 'no signal')
"""

# The grader ignores SIGINT, as a pytest-xdist worker or a `&` background job does, so the
# group signal cannot end the grading early and the job is still there to answer.
GRADER = """
import signal, sys
from pathlib import Path
signal.signal(signal.SIGINT, signal.SIG_IGN)
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import run_job
run = run_job(Path(sys.argv[1]), 11, Limits(wall_seconds=60), 'tok-group-sigint',
              argv=['-c', sys.argv[2]])
print(run.returncode, run.output, flush=True)
"""


def _until(path: Path, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert time.monotonic() < deadline, f'{path.name} never appeared'
        time.sleep(0.02)


def test_a_sigint_to_the_graders_group_does_not_reach_the_job(tmp_path: Path) -> None:
    # The grader leads a group of its own here, so the test can signal that group and not
    # pytest's.
    grader = subprocess.Popen([sys.executable, '-c', GRADER, str(tmp_path), JOB],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              start_new_session=True)
    try:
        _until(tmp_path / 'ready', 60)
        os.killpg(grader.pid, signal.SIGINT)
        (tmp_path / 'sent').touch()
        out, _ = grader.communicate(timeout=60)
    finally:
        if grader.poll() is None:
            grader.kill()
            grader.wait()
    assert (tmp_path / 'answer').read_text() == 'no signal', out
    assert out.startswith('0 '), out


def test_stop_jobs_ends_running_jobs_and_refuses_new_ones(tmp_path: Path) -> None:
    """What the grader's Ctrl-C does now that its jobs do not get the terminal's SIGINT."""
    import threading

    from robot_lab.grading.package.rubric import Limits
    from robot_lab.grading.package.sandbox import run_job, stop_jobs

    sleeper = 'import sys, time\nfrom pathlib import Path\n' \
              '(Path(sys.argv[-1]) / "ready").touch()\ntime.sleep(300)\n'
    runs: list[object] = []
    first = tmp_path / 'first'
    first.mkdir()
    worker = threading.Thread(target=lambda: runs.append(run_job(
        first, 11, Limits(wall_seconds=300), 'tok-stop-jobs', argv=['-c', sleeper])))
    worker.start()
    try:
        _until(first / 'ready', 60)
        started = time.monotonic()
        stop_jobs()
        worker.join(60)
        assert not worker.is_alive() and time.monotonic() - started < 30
        later = tmp_path / 'later'
        later.mkdir()
        refused = run_job(later, 11, Limits(wall_seconds=300), 'tok-stop-jobs',
                          argv=['-c', sleeper])
        assert refused.returncode is not None and refused.returncode != 0
        assert refused.elapsed < 30
    finally:
        stop_jobs(False)
        worker.join(10)
    assert len(runs) == 1
