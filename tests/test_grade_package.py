"""Package grading for a whole class (issue 12): one real run of `robot-lab grade DIR
--lab ch6-lab1 -o OUT --jobs 2` over correct, renamed, plagiarised and faulty packages,
each built with colcon, launched and watched live; then every student's marks, the
outputs an instructor reads, and that nothing is left running. Also the LMS layouts and
the sandbox's promise that nothing outlives a grader killed with SIGKILL."""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from collections.abc import Callable
from pathlib import Path

import psutil
import pytest
from conftest import REPO, run_cli

from robot_lab.grading.package.sandbox import JOB_LOGS_VAR, TOKEN_VAR, namespaces_available
from robot_lab.grading.package.submission import find_package, find_submissions

DATA = REPO / 'tests' / 'data' / 'class_ch6'
ALL = ('builds', 'launch_file', 'sensor_publishes', 'controller_commands', 'actuator_logs',
       'params_file', 'params_used', 'readme')
POINTS = {'builds': 2, 'launch_file': 2, 'sensor_publishes': 2, 'controller_commands': 2,
          'actuator_logs': 2, 'params_file': 1, 'params_used': 1, 'readme': 1}
PKG = 'robot_system'
# One class run: ~90 s on a quiet 2-core machine, 6-11 min at load averages of 15-50 (the
# time is the bench's business, bench/bench_grading.py; here only that it ends).
pytestmark = pytest.mark.timeout(1800)


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f'{old!r} not in {path}'
    path.write_text(text.replace(old, new))


def _no_param_load(pkg: Path) -> None:
    launch = pkg / 'launch' / 'robot.launch.xml'
    text = launch.read_text()
    lines = [line for line in text.splitlines() if '<param from=' not in line]
    launch.write_text('\n'.join(lines) + '\n')


def _wrong_topic(pkg: Path) -> None:
    _edit(pkg / PKG / 'controller_node.py', "(Float32, 'distance',", "(Float32, 'distance_m',")


def _flat_params(pkg: Path) -> None:
    (pkg / 'config' / 'params.yaml').write_text(
        'publish_rate: 10.0\nnoise_level: 0.05\ntarget_distance: 1.5\ngain: 0.8\n')


def _actuator_crash(pkg: Path) -> None:
    _edit(pkg / PKG / 'actuator_node.py', "        super().__init__('wheel_actuator')\n",
          "        super().__init__('wheel_actuator')\n"
          "        raise RuntimeError('motor driver /dev/ttyUSB0 not found')\n")


def _actuator_silent(pkg: Path) -> None:
    _edit(pkg / PKG / 'actuator_node.py',
          "        self.get_logger().info(f'{self.motor}: drive at {msg.linear.x:+.2f} m/s')",
          '        self.last_speed = msg.linear.x')


def _two_params(pkg: Path) -> None:
    (pkg / 'config' / 'params.yaml').write_text(
        'range_sensor:\n  ros__parameters:\n    publish_rate: 10.0\n'
        'distance_controller:\n  ros__parameters:\n    gain: 0.8\n')


def _no_launch(pkg: Path) -> None:
    shutil.rmtree(pkg / 'launch')


def _no_readme(pkg: Path) -> None:
    (pkg / 'README.md').unlink()


def _setup_syntax(pkg: Path) -> None:
    _edit(pkg / 'setup.py', "    version='0.0.1',\n", "    version='0.0.1'\n    zip_safe=(,\n")


def _busy_controller(pkg: Path) -> None:
    _edit(pkg / PKG / 'controller_node.py', 'def main(args=None):\n',
          'def main(args=None):\n    ticks = 0\n    while True:  # "calibrating" forever\n'
          '        ticks += 1\n')


def _flood_sensor(pkg: Path) -> None:
    _edit(pkg / PKG / 'sensor_node.py', '        self.phase = 0.0\n',
          '        self.phase = 0.0\n        import threading\n'
          '        threading.Thread(target=self.chatter, daemon=True).start()\n')
    _edit(pkg / PKG / 'sensor_node.py', '    def tick(self):\n',
          '    def chatter(self):\n        while rclpy.ok():\n'
          "            self.get_logger().info('adc sample ok')\n"
          "            for _ in range(1000):\n"
          "                print('adc raw 0x3ff ok')\n\n    def tick(self):\n")


FAULTS: dict[str, tuple[Callable[[Path], None], set[str]]] = {
    'no_param_load': (_no_param_load, {'params_used'}),
    'wrong_topic': (_wrong_topic, {'controller_commands', 'actuator_logs'}),
    'flat_params': (_flat_params, {'params_file', 'params_used'}),
    'actuator_crash': (_actuator_crash, {'actuator_logs', 'params_used'}),  # dead: unused
    'actuator_silent': (_actuator_silent, {'actuator_logs'}),
    'two_params': (_two_params, {'params_file'}),
    'no_launch': (_no_launch, {'launch_file', 'params_used'}),
    'no_readme': (_no_readme, {'readme'}),
    'setup_syntax': (_setup_syntax, {'builds', 'sensor_publishes', 'controller_commands',
                                     'actuator_logs', 'params_used'}),
    'busy_controller': (_busy_controller, {'controller_commands', 'actuator_logs',
                                           'params_used'}),  # never up: unused
    'flood_sensor': (_flood_sensor, {'sensor_publishes'}),
}
CORRECT = ('alice', 'bob', 'carol', 'olivia', 'mallory')


def make_class(root: Path) -> Path:
    """The acceptance class: five correct variants and one student per fault."""
    ref = DATA / 'reference'
    shutil.copytree(ref, root / 'alice')
    with zipfile.ZipFile(root / 'bob.zip', 'w') as zf:  # the same, zipped with its folder
        for path in sorted(ref.rglob('*')):
            zf.write(path, f'{PKG}/{path.relative_to(ref)}')
    carol = root / 'carol'  # a workspace with the student's own build/install/log
    shutil.copytree(ref, carol / 'src' / PKG)
    for stray in ('build/robot_system/lib', 'install/robot_system/share', 'log/latest'):
        (carol / stray).mkdir(parents=True)
        (carol / stray / 'junk.txt').write_text('left over from the student machine\n')
    (carol / 'install' / 'setup.bash').write_text('exit 1\n')
    shutil.copytree(DATA / 'other_names', root / 'olivia')
    shutil.copytree(ref, root / 'mallory')
    shutil.copytree(DATA / 'plagiarised' / PKG, root / 'mallory' / PKG, dirs_exist_ok=True)
    for name, (fault, _lost) in FAULTS.items():
        shutil.copytree(ref, root / name)
        fault(root / name)
    return root


def _job_processes(token: str | None = None, run: str | None = None) -> list[psutil.Process]:
    """Processes of grading jobs (carrying the job token): of the job `token`, or of the
    grader started with RUN_VAR=`run` (jobs inherit the grader's environment), so another
    test module grading at the same time on another worker is not counted."""
    found = []
    for proc in psutil.process_iter():
        try:
            env = proc.environ()
        except psutil.Error:
            continue
        value = env.get(TOKEN_VAR)
        if value is not None and token in (None, value) and run in (None, env.get(RUN_VAR)):
            found.append(proc)
    return found


RUN_VAR = 'ROBOT_LAB_TEST_GRADE_RUN'


@pytest.fixture(scope='module')
def graded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    root = make_class(tmp_path_factory.mktemp('class'))
    out = tmp_path_factory.mktemp('out')
    run = f'class-{os.getpid()}-{time.monotonic_ns()}'
    started = time.monotonic()
    logs = tmp_path_factory.mktemp('job_logs')
    done = run_cli('grade', str(root), '--lab', 'ch6-lab1', '-o', str(out), '--jobs', '2',
                   timeout=1500, env={RUN_VAR: run, JOB_LOGS_VAR: str(logs)})
    elapsed = time.monotonic() - started
    leftovers = _job_processes(run=run)
    return {'done': done, 'out': out, 'elapsed': elapsed, 'leftovers': leftovers, 'logs': logs,
            'root': root}


def _explain(graded: dict[str, object], student: str) -> str:
    """The student's feedback and the end of its job's log (steps, waits, node output)."""
    out, logs = graded['out'], graded['logs']
    assert isinstance(out, Path) and isinstance(logs, Path)
    feedback = (out / 'feedback' / f'{student}.md').read_text()
    log = logs / f'{student}.log'
    tail = log.read_text(errors='replace')[-6000:] if log.is_file() else '(no job log)'
    return f'{feedback}\n--- job log ---\n{tail}'


def _grades(out: Path) -> dict[str, dict[str, str]]:
    with (out / 'grades.csv').open() as f:
        return {row['student']: row for row in csv.DictReader(f)}


def test_run_exits_0_and_leaves_nothing_running(graded: dict[str, object]) -> None:
    done = graded['done']
    assert isinstance(done, subprocess.CompletedProcess)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert graded['leftovers'] == []
    print(f'class of {len(CORRECT) + len(FAULTS)} graded in {graded["elapsed"]:.0f} s')


def test_gradebook_has_every_student_and_check(graded: dict[str, object]) -> None:
    out = graded['out']
    assert isinstance(out, Path)
    with (out / 'grades.csv').open() as f:
        header = next(csv.reader(f))
    assert header == ['student', 'score', 'max_score', *ALL]
    assert set(_grades(out)) == {*CORRECT, *FAULTS}


@pytest.mark.parametrize('student', CORRECT)
def test_correct_variants_get_full_marks(graded: dict[str, object], student: str) -> None:
    out = graded['out']
    assert isinstance(out, Path)
    row = _grades(out)[student]
    assert row['score'] == row['max_score'] == '13', _explain(graded, student)


@pytest.mark.parametrize('student', sorted(FAULTS))
def test_faulty_variants_lose_exactly_their_checks(graded: dict[str, object],
                                                   student: str) -> None:
    out = graded['out']
    assert isinstance(out, Path)
    row = _grades(out)[student]
    lost = {c for c in ALL if row[c] != str(POINTS[c])}
    assert lost == FAULTS[student][1], _explain(graded, student)


def test_feedback_explains_and_shows_the_graph(graded: dict[str, object]) -> None:
    out = graded['out']
    assert isinstance(out, Path)
    alice = (out / 'feedback' / 'alice.md').read_text()
    assert '**Expected:**' in alice and '**Observed:**' in alice
    assert '/distance' in alice and '/cmd_vel' in alice  # topics seen, found by role
    assert 'drive at' in alice  # the actuator's last log lines
    assert '![your running graph](data:image/png;base64,' in alice  # embedded: shows anywhere
    assert (out / 'feedback' / 'alice.graph.png').read_bytes()[:4] == b'\x89PNG'
    page = (out / 'feedback' / 'alice.html').read_text()  # each check once, no table
    assert '<strong>Observed:</strong>' in page and page.count('<table>') == 0
    # A failed build names colcon's file and line; a flat file gets the rcl fix.
    syntax = (out / 'feedback' / 'setup_syntax.md').read_text()
    assert 'setup.py' in syntax and 'line' in syntax.lower()
    flat = (out / 'feedback' / 'flat_params.md').read_text()
    assert 'ros__parameters' in flat and 'params.yaml:1' in flat
    crash = (out / 'feedback' / 'actuator_crash.md').read_text()
    assert 'motor driver /dev/ttyUSB0 not found' in crash
    flood = (out / 'feedback' / 'flood_sensor.md').read_text()
    assert 'lines/s' in flood


def test_gradescope_results(graded: dict[str, object]) -> None:
    out = graded['out']
    assert isinstance(out, Path)
    data = json.loads((out / 'results' / 'wrong_topic.json').read_text())
    assert data['score'] == 9
    assert data['tests'][0]['name'] == 'The package builds with colcon'
    assert all({'name', 'score', 'max_score', 'output'} <= set(t) for t in data['tests'])


def test_similarity_names_the_copy_not_the_honest_student(graded: dict[str, object]) -> None:
    out = graded['out']
    assert isinstance(out, Path)
    page = (out / 'similarity.html').read_text()
    named = {frozenset(m) for m in re.findall(r'<tr data-a="([^"]+)" data-b="([^"]+)">', page)}
    assert frozenset({'alice', 'mallory'}) in named
    assert not any('olivia' in p for p in named)


def test_lms_layouts_and_package_places(tmp_path: Path) -> None:
    """Moodle and Canvas downloads; package at top, one level down, in src/."""
    moodle = tmp_path / 'moodle'
    (moodle / 'Jane Doe_1234567_assignsubmission_file_' / 'robot_system').mkdir(parents=True)
    canvas = tmp_path / 'canvas'
    canvas.mkdir()
    (canvas / 'doejane_12345_67890_robot_system.zip').write_bytes(b'')
    (canvas / 'smithjo_LATE_2345_7890_pkg.zip').write_bytes(b'')
    assert [s.student for s in find_submissions(moodle)] == ['Jane Doe_1234567']
    assert [s.student for s in find_submissions(canvas)] == ['doejane', 'smithjo']
    assert [s.student for s in find_submissions(DATA / 'reference')] == ['reference']
    ws = tmp_path / 'ws'
    shutil.copytree(DATA / 'reference', ws / 'src' / PKG)
    (ws / 'build' / 'other').mkdir(parents=True)
    (ws / 'build' / 'other' / 'package.xml').write_text('<package/>')
    assert find_package(ws) == ws / 'src' / PKG
    assert find_package(ws / 'src') == ws / 'src' / PKG


@pytest.mark.skipif(not namespaces_available(), reason='no unprivileged namespaces here')
def test_nothing_outlives_a_grader_killed_with_sigkill(tmp_path: Path) -> None:
    """A job whose process double-forks a daemon: kill -9 the grader, the daemon dies."""
    job = tmp_path / 'job'
    job.mkdir()
    marker = tmp_path / 'daemon-started'
    daemon = ('import os, time\n'
              'if os.fork() == 0:\n'
              '    os.setsid()\n'
              '    if os.fork() == 0:\n'
              f'        open({str(marker)!r}, "w").close()\n'
              '        time.sleep(300)\n'
              '    os._exit(0)\n'
              'time.sleep(300)\n')
    grader = ('import sys\nfrom pathlib import Path\n'
              'from robot_lab.grading.package.rubric import Limits\n'
              'from robot_lab.grading.package.sandbox import run_job\n'
              f'run_job(Path({str(job)!r}), 11, Limits(), "tok-sigkill-test", '
              f'argv=["-c", {daemon!r}])\n')
    proc = subprocess.Popen([sys.executable, '-c', grader], env=dict(os.environ))
    try:
        deadline = time.monotonic() + 30
        while not marker.exists():
            assert time.monotonic() < deadline, 'the job never started its daemon'
            assert proc.poll() is None
            time.sleep(0.05)
        assert _job_processes('tok-sigkill-test')
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        deadline = time.monotonic() + 10
        while _job_processes('tok-sigkill-test'):
            assert time.monotonic() < deadline, 'a job process outlived the grader'
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            proc.kill()


FORK_BOMB = """
import os, sys, time
from robot_lab.grading.package.rubric import Limits
from robot_lab.grading.package.sandbox import enter
enter(Limits(processes=48), bool(os.environ.get('ROBOT_LAB_GRADE_ISOLATED')))
forked = 0
try:
    for _ in range(400):
        if os.fork() == 0:
            time.sleep(60)
            os._exit(0)
        forked += 1
except OSError as exc:
    print('refused after', forked, exc.errno, flush=True)
else:
    print('forked all', forked, flush=True)
"""


def test_a_fork_bomb_stops_at_the_process_limit(tmp_path: Path) -> None:
    """The rubric's `processes` binds a job whoever runs the grader: the rlimit for a user,
    a pids cgroup for root (whom RLIMIT_NPROC does not bind)."""
    from robot_lab.grading.package.rubric import Limits
    from robot_lab.grading.package.sandbox import run_job

    run = run_job(tmp_path, 11, Limits(processes=48, wall_seconds=60), 'tok-fork-bomb',
                  argv=['-c', FORK_BOMB])
    found = re.search(r'refused after (\d+) 11', run.output)
    assert found, run.output  # EAGAIN before 400 forks
    assert int(found.group(1)) <= 48
    assert not _job_processes('tok-fork-bomb')
    assert not Path('/sys/fs/cgroup/pids/robot_lab-tok-fork-bomb').exists()
