"""Grading a class an instructor can leave running (issue 19): every entry gets a row,
archives are unpacked safely, checks are behavioural and fair, feedback follows the cause,
and a hostile student's job is contained. The class is graded for real (colcon, the
student's launch file, a live graph); the archive rules are checked without ROS."""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import os
import shutil
import socket
import tarfile
import time
import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import psutil
import pytest
from conftest import REPO, run_cli

from robot_lab.errors import RobotLabError
from robot_lab.grading.package.submission import find_submissions, unpack
from robot_lab.grading.report import safe_name

DATA = REPO / 'tests' / 'data' / 'class_ch6'
PKG = 'robot_system'
POINT_COLUMNS = ('builds', 'launch_file', 'sensor_publishes', 'controller_commands',
                 'actuator_logs', 'params_file', 'params_used', 'readme')
pytestmark = pytest.mark.timeout(1800)


def _tar(path: Path, members: dict[str, bytes], links: dict[str, str] | None = None,
         mode: str = 'w:gz') -> Path:
    with tarfile.open(path, mode) as tf:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tf.addfile(info, io.BytesIO(data))
        for name, target in (links or {}).items():
            info = tarfile.TarInfo(name)
            info.type = tarfile.SYMTYPE
            info.linkname = target
            tf.addfile(info)
    return path


def _package_tar(path: Path, mode: str) -> Path:
    with tarfile.open(path, mode) as tf:
        tf.add(DATA / 'reference', arcname=PKG)
    return path


@pytest.mark.parametrize('suffix,mode', [('.tar.gz', 'w:gz'), ('.tgz', 'w:gz'),
                                         ('.tar', 'w'), ('.tar.xz', 'w:xz'),
                                         ('.tar.bz2', 'w:bz2')])
def test_tar_archives_are_entries_like_zips(tmp_path: Path, suffix: str, mode: str) -> None:
    _package_tar(tmp_path / f'gus{suffix}', mode)
    [sub] = find_submissions(tmp_path)
    assert sub.student == 'gus'
    package = unpack(sub, tmp_path / 'out')
    assert (package / 'package.xml').is_file() and package.name == PKG


def test_unsafe_archive_members_never_leave_the_folder(tmp_path: Path) -> None:
    outside = tmp_path / 'outside'
    outside.mkdir()
    (tmp_path / 'class').mkdir()
    _tar(tmp_path / 'class' / 'eve.tar.gz', {
        f'{PKG}/package.xml': b'<package><name>robot_system</name></package>',
        '../outside/escaped.txt': b'x', '/tmp/absolute.txt': b'x',
    }, links={f'{PKG}/link': str(outside), f'{PKG}/up': '../../outside'})
    package = unpack(find_submissions(tmp_path / 'class')[0], tmp_path / 'job')
    assert package == tmp_path / 'job' / PKG
    assert not (outside / 'escaped.txt').exists() and not Path('/tmp/absolute.txt').exists()
    assert not any(p.is_symlink() for p in (tmp_path / 'job').rglob('*'))
    with zipfile.ZipFile(tmp_path / 'class' / 'zed.zip', 'w') as zf:
        zf.writestr(f'{PKG}/package.xml', '<package/>')
        zf.writestr('../outside/zipped.txt', 'x')
    unpack(find_submissions(tmp_path / 'class')[1], tmp_path / 'job2')
    assert not (outside / 'zipped.txt').exists()


def test_a_bomb_stops_at_the_size_cap(tmp_path: Path) -> None:
    with zipfile.ZipFile(tmp_path / 'bomb.zip', 'w', zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(f'{PKG}/big.bin', b'\0' * (60 << 20))
    with pytest.raises(RobotLabError, match=r'bomb\.zip expands to more than 50 MB'):
        unpack(find_submissions(tmp_path / 'bomb.zip')[0], tmp_path / 'job')


def _odd_entries(root: Path) -> dict[str, str]:
    """Entries that hold no package, and the words their feedback must say."""
    root.mkdir(parents=True, exist_ok=True)
    (root / 'rita.rar').write_bytes(b'Rar!\x1a\x07\x00' + b'\0' * 64)
    (root / 'pete.py').write_text('import rclpy\n')
    with zipfile.ZipFile(root / 'emma.zip', 'w'):
        pass
    folder = root / 'Otto Ode_7654321_assignsubmission_file_'
    folder.mkdir()
    (folder / 'otto.rar').write_bytes(b'Rar!')
    return {'rita': 'rita.rar is a .rar file', 'pete': 'pete.py is a .py file',
            'emma': 'emma.zip is empty', 'Otto Ode_7654321': 'otto.rar is a .rar file'}


def test_entries_without_a_package_say_which_file_and_what_to_hand_in(tmp_path: Path) -> None:
    expected = _odd_entries(tmp_path / 'class')
    subs = {s.student: s for s in find_submissions(tmp_path / 'class')}
    assert set(subs) == set(expected)
    for student, words in expected.items():
        with pytest.raises(RobotLabError) as caught:
            unpack(subs[student], tmp_path / 'job' / student)
        assert words in caught.value.message, caught.value.message
        assert '.zip or .tar.gz' in (caught.value.fix or '')
        assert str(tmp_path) not in str(caught.value)  # no grader path
    listed = run_cli('grade', str(tmp_path / 'class'), '--lab', 'ch6-lab1', '--list')
    assert listed.returncode == 0, listed.stderr
    for student, words in expected.items():
        line = next(x for x in listed.stdout.splitlines() if x.startswith(student))
        assert 'NOT GRADABLE' in line and words in line, listed.stdout


# ---------------------------------------------------------------------------------------
# The class: graded for real, once, at --jobs 2.

ALL_POINTS = 13


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f'{old!r} not in {path}'
    path.write_text(text.replace(old, new))


def _one_process(pkg: Path) -> None:
    """All three nodes spun by one executable (a MultiThreadedExecutor)."""
    (pkg / PKG / 'all_nodes.py').write_text(
        'import rclpy\nfrom rclpy.executors import MultiThreadedExecutor\n'
        'from robot_system.actuator_node import WheelActuator\n'
        'from robot_system.controller_node import DistanceController\n'
        'from robot_system.sensor_node import RangeSensor\n\n\n'
        'def main(args=None):\n    rclpy.init(args=args)\n'
        '    executor = MultiThreadedExecutor()\n'
        '    for node in (RangeSensor(), DistanceController(), WheelActuator()):\n'
        '        executor.add_node(node)\n'
        '    try:\n        executor.spin()\n    except KeyboardInterrupt:\n        pass\n'
        '    finally:\n        rclpy.try_shutdown()\n')
    _edit(pkg / 'setup.py', "            'actuator_node = robot_system.actuator_node:main',\n",
          "            'actuator_node = robot_system.actuator_node:main',\n"
          "            'all_nodes = robot_system.all_nodes:main',\n")
    (pkg / 'launch' / 'robot.launch.xml').write_text(
        '<launch>\n  <node pkg="robot_system" exec="all_nodes" output="screen">\n'
        '    <param from="$(find-pkg-share robot_system)/config/params.yaml"/>\n'
        '  </node>\n</launch>\n')
    (pkg / 'README.md').write_text('# robot_system\n\nBuild with colcon, then launch '
                                   '`robot.launch.xml`: one process runs all three nodes.\n')


def _ignores_input(pkg: Path) -> None:
    _edit(pkg / PKG / 'controller_node.py',
          'speed = max(-limit, min(limit, gain * (msg.data - target)))', 'speed = 0.5')


def _laggy(pkg: Path) -> None:
    """An honest controller that takes 80 ms a reading, as one can on a loaded host: it
    keeps up with the 10 Hz sensor, but fed at 20 Hz its queue of 10 readings fills and its
    commands trail the input by 0.8 s."""
    node = pkg / PKG / 'controller_node.py'
    _edit(node, 'import rclpy\n', 'import time\n\nimport rclpy\n')
    _edit(node, '    def on_distance(self, msg):\n',
          '    def on_distance(self, msg):\n        time.sleep(0.08)\n')


def _saturated(pkg: Path) -> None:
    _edit(pkg / 'config' / 'params.yaml', 'gain: 0.8', 'gain: 50.0')


def _syntax_error(pkg: Path) -> None:
    _edit(pkg / PKG / 'controller_node.py', 'def on_distance(self, msg):',
          'def on_distance(self, msg)')


def _missing_module(pkg: Path) -> None:
    _edit(pkg / 'setup.py', "'controller_node = robot_system.controller_node:main'",
          "'controller_node = robot_system.controler_node:main'")


def _wrong_type(pkg: Path) -> None:
    _edit(pkg / 'config' / 'params.yaml', 'gain: 0.8', "gain: '0.8'")


HOSTILE = """
import os, signal, socket, subprocess, sys, time


def attempts(node_log):
    def attempt(what, action):
        try:
            action()
            node_log(f'{what}: done')
        except Exception as err:
            node_log(f'{what}: {type(err).__name__}: {err}')

    attempt('write outside', lambda: open(@OUTSIDE@, 'w').write('pwned'))
    attempt('write /tmp', lambda: open('/tmp/leo_was_here', 'w').write('pwned'))
    attempt('tamper', lambda: open(@SIBLING@, 'a').write('pwned'))
    attempt('read ssh', lambda: open(@SSH@).read())
    attempt('signal parent', lambda: os.kill(os.getppid(), signal.SIGTERM))
    attempt('signal grader', lambda: os.kill(@GRADER@, signal.SIGTERM))
    attempt('connect', lambda: socket.create_connection(('127.0.0.1', @PORT@), 2))
    job = os.path.dirname(os.environ['ROBOT_LAB_WORKSPACE'])  # full marks, forged
    attempt('forge', lambda: open(os.path.join(job, 'report.json'), 'w').write(
        '{"student": "hostile", "checks": [{"id": "builds", "name": "x", "score": 99, '
        '"max_score": 2, "output": ""}]}'))
    if os.fork() == 0:  # a daemon that outlives its node
        os.setsid()
        if os.fork() == 0:
            os.execvp(sys.executable, [sys.executable, '-c',
                      'import time; time.sleep(900)  # robot_lab_hostile_daemon'])
        os._exit(0)
"""


def _hostile(pkg: Path, root: Path, port: int) -> None:
    """A working system whose sensor tries everything a job must not do."""
    code = HOSTILE
    for key, value in (('@OUTSIDE@', repr(str(root.parent / 'pwned.txt'))),
                       ('@SIBLING@', repr(str(root / 'alice' / 'README.md'))),
                       ('@SSH@', repr(str(Path.home() / '.ssh' / 'id_rsa'))),
                       ('@GRADER@', str(os.getpid())), ('@PORT@', str(port))):
        code = code.replace(key, value)
    (pkg / PKG / 'mischief.py').write_text(code)
    _edit(pkg / PKG / 'sensor_node.py', "        self.get_logger().info(f'range sensor publishing "
          "at {rate} Hz')\n", "        self.get_logger().info(f'range sensor publishing at "
          "{rate} Hz')\n        from robot_system.mischief import attempts\n"
          '        attempts(lambda text: print(text, flush=True))\n')


# Honest code that looks around the machine it runs on, as libraries do (issue 51: a job's
# uid had no passwd entry, and a correct package lost 7 of 13 points).
LOOK_AROUND = """
import getpass, grp, locale, os, pwd, socket


def look_around():
    user = getpass.getuser()
    entry = pwd.getpwnam(user)
    mine = pwd.getpwuid(os.getuid())
    group = grp.getgrgid(os.getgid()).gr_name
    home = os.path.expanduser('~')
    for folder in (home, mine.pw_dir, entry.pw_dir):
        os.makedirs(os.path.join(folder, '.config', 'robot_system'), exist_ok=True)
        with open(os.path.join(folder, '.config', 'robot_system', 'seen'), 'a') as f:
            f.write(user + '\\n')
    locale.setlocale(locale.LC_ALL, '')
    'caf\\u00e9'.encode(locale.getpreferredencoding())
    socket.getaddrinfo('localhost', 7400)
    socket.gethostbyname(socket.gethostname())
    with open('/dev/null', 'w') as sink:
        sink.write('nothing')
    with open('/dev/urandom', 'rb') as noise:
        assert len(noise.read(16)) == 16
    assert len(os.urandom(16)) == 16
    assert os.listdir('/proc/self/fd') and 'Pid:' in open('/proc/self/status').read()
    return f'{user} ({mine.pw_uid}, {group}) at home in {home}'
"""


def _looks_around(pkg: Path) -> None:
    """Every node asks who and where it is before it starts (a correct system)."""
    (pkg / PKG / 'machine.py').write_text(LOOK_AROUND)
    for node in ('sensor_node', 'controller_node', 'actuator_node'):
        path = pkg / PKG / f'{node}.py'
        _edit(path, 'import rclpy\n',
              'import rclpy\n\nfrom robot_system.machine import look_around\n')
        text = path.read_text()
        start = text.index('super().__init__(')
        end = text.index('\n', start) + 1
        path.write_text(text[:end] + '        self.get_logger().info(look_around())\n'
                        + text[end:])


VARIANTS: dict[str, Callable[[Path], None]] = {
    'solo': _one_process, 'ignorer': _ignores_input, 'saturated': _saturated,
    'laggy': _laggy, 'machine': _looks_around,
    'syntax': _syntax_error, 'missing_module': _missing_module, 'wrong_type': _wrong_type,
}


RUN_VAR = 'ROBOT_LAB_TEST_GRADE_RUN'


def _environ(proc: psutil.Process) -> dict[str, str]:
    try:
        return dict(proc.environ())
    except psutil.Error:
        return {}


def _tree_digest(root: Path) -> str:
    digest = hashlib.sha256()
    for path in sorted(root.rglob('*')):
        if path.is_file():
            digest.update(str(path.relative_to(root)).encode() + path.read_bytes())
    return digest.hexdigest()


@pytest.fixture(scope='module')
def graded(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    base = tmp_path_factory.mktemp('contained')
    root = base / 'class'
    shutil.copytree(DATA / 'reference', root / 'alice')
    for name, change in VARIANTS.items():
        shutil.copytree(DATA / 'reference', root / name)
        change(root / name)
    _package_tar(root / 'gus.tar.gz', 'w:gz')
    odd = _odd_entries(root)
    ssh = Path.home() / '.ssh'
    ssh.mkdir(parents=True, exist_ok=True)
    (ssh / 'id_rsa').write_text('PRIVATE KEY\n')
    listener = socket.socket()
    listener.bind(('127.0.0.1', 0))
    listener.listen(8)
    listener.setblocking(False)
    shutil.copytree(DATA / 'reference', root / 'hostile')
    _hostile(root / 'hostile', root, listener.getsockname()[1])
    before = {name: _tree_digest(root / name) for name in ('alice', 'solo')}
    out = base / 'out'
    run = f'contained-{os.getpid()}-{time.monotonic_ns()}'  # this run's processes carry it
    done = run_cli('grade', str(root), '--lab', 'ch6-lab1', '-o', str(out), '--jobs', '2',
                   timeout=1500, env={RUN_VAR: run})
    connections = 0
    with contextlib.suppress(BlockingIOError):
        while listener.accept():
            connections += 1
    listener.close()
    daemons = [p for p in psutil.process_iter(['cmdline'])
               if 'robot_lab_hostile_daemon' in ' '.join(p.info['cmdline'] or [])
               and _environ(p).get(RUN_VAR) == run]
    yield {'done': done, 'out': out, 'root': root, 'odd': odd, 'before': before,
           'connections': connections, 'daemons': daemons, 'base': base}


def _grades(out: Path) -> dict[str, dict[str, str]]:
    with (out / 'grades.csv').open() as f:
        return {row['student']: row for row in csv.DictReader(f)}


def _feedback(graded: dict[str, Any], student: str) -> str:
    return (graded['out'] / 'feedback' / f'{safe_name(student)}.md').read_text()


def test_every_entry_has_a_row_and_the_run_exits_0(graded: dict[str, Any]) -> None:
    done = graded['done']
    assert done.returncode == 0, done.stdout + done.stderr
    # Said before the first job, on stderr (stdout may be --json): how the jobs are held.
    assert done.stderr.startswith('containment: each job in its own namespaces'), done.stderr
    grades = _grades(graded['out'])
    expected = {'alice', 'gus', 'hostile', *VARIANTS, *graded['odd']}
    assert set(grades) == expected, done.stdout
    for student, words in graded['odd'].items():
        assert grades[student]['score'] in ('0', 'not graded'), grades[student]
        assert all(grades[student][c] in ('0', '') for c in POINT_COLUMNS), grades[student]
        text = _feedback(graded, student)
        assert words in text and '.zip or .tar.gz' in text
        assert str(graded['base']) not in text and 'robot_lab_grade_' not in text


@pytest.mark.parametrize('student', ['alice', 'gus', 'solo', 'saturated', 'laggy', 'hostile',
                                     'machine'])
def test_correct_systems_get_full_marks(graded: dict[str, Any], student: str) -> None:
    row = _grades(graded['out'])[student]
    assert row['score'] == str(ALL_POINTS), (row, _feedback(graded, student))


def test_one_process_with_three_nodes_is_a_launch_file_that_starts_all(
        graded: dict[str, Any]) -> None:
    text = _feedback(graded, 'solo')
    assert 'started 1 process(es) with 3 node(s)' in text
    assert 'relaunched' in text or 'remapped' in text  # the sensor could not be paused alone


def test_an_input_ignoring_controller_loses_only_its_check(graded: dict[str, Any]) -> None:
    row = _grades(graded['out'])['ignorer']
    lost = [c for c in POINT_COLUMNS if row[c] == '0']
    assert lost == ['controller_commands'], row
    assert 'did not follow the input' in _feedback(graded, 'ignorer')
    assert 'its commands follow the input' in _feedback(graded, 'saturated')


def test_a_crash_is_told_from_the_students_own_source(graded: dict[str, Any]) -> None:
    syntax = _feedback(graded, 'syntax')
    assert '`robot_system/controller_node.py` line' in syntax
    assert 'def on_distance(self, msg)' in syntax and 'SyntaxError' in syntax
    missing = _feedback(graded, 'missing_module')
    assert 'setup.py line' in missing and 'robot_system.controler_node' in missing
    assert "subscribe to exactly the sensor's topic" not in missing
    wrong = _feedback(graded, 'wrong_type')
    assert 'config/params.yaml line' in wrong and "gain: '0.8'" in wrong
    assert 'create a timer' not in wrong
    assert _grades(graded['out'])['wrong_type']['params_used'] == '0'  # its node died
    for student in (*VARIANTS, 'alice', 'hostile', 'gus'):
        text = _feedback(graded, student)
        assert 'site-packages' not in text and 'robot_lab_grade_' not in text, student
        if student != 'hostile':  # its notes quote the paths it tried itself
            assert str(graded['base']) not in text, student


def test_the_hostile_student_is_contained_and_told(graded: dict[str, Any]) -> None:
    root, base = graded['root'], graded['base']
    assert not (base / 'pwned.txt').exists()
    assert not Path('/tmp/leo_was_here').exists()
    assert 'pwned' not in (root / 'alice' / 'README.md').read_text()
    assert graded['before'] == {n: _tree_digest(root / n) for n in graded['before']}
    assert graded['connections'] == 0
    assert graded['daemons'] == []
    text = _feedback(graded, 'hostile')
    notes = [line for line in text.splitlines() if line.startswith('> **Sandbox:**')]
    joined = '\n'.join(notes)
    assert 'Read-only file system' in joined or 'does not exist in the sandbox' in joined
    assert 'SIGTERM' in joined  # its parent, the grading job, ignored it
    assert 'network connection was refused' in joined
    assert 'outlived the launch' in joined
    assert 'PRIVATE KEY' not in text

