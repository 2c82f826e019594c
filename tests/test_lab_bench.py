"""The student's JupyterLab is a lab bench: ROS terminals, the course copy as its root.

`./kit start` / `./kit lab` run JupyterLab with config/jupyter/jupyter_server_config.py:
its terminals run bash with config/jupyter/ros_terminal.bashrc, which must give a working
ROS 2 shell even when the PATH it inherits lost the kit's venv (Debian's /etc/profile does
that to a login shell), in the student's own ROS domain, starting in the course folder.
These tests start the real shell, and `./kit lab` on a scratch home: a real Jupyter server
and a real terminal over its websocket. No browser (bench/browser_check.py does that).
"""

from __future__ import annotations

import asyncio
import hashlib
import json
import os
import re
import socket
import subprocess
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from lab_chromium import headless_chromium

from robot_lab.process import spawn, stop

ROOT = Path(__file__).resolve().parents[1]
VENV = Path(os.environ.get('ROBOT_LAB_VENV', ROOT / '.venv'))
CONFIG = ROOT / 'config' / 'jupyter' / 'jupyter_server_config.py'
RCFILE = ROOT / 'config' / 'jupyter' / 'ros_terminal.bashrc'
# What a login shell's /etc/profile leaves on Debian: no venv.
LOGIN_PATH = '/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin'


def _clean_env(tmp_path: Path, **extra: str) -> dict[str, str]:
    home = tmp_path / 'home'
    home.mkdir(exist_ok=True)
    env = {'PATH': LOGIN_PATH, 'HOME': str(home), 'TERM': 'dumb', 'LANG': 'C.UTF-8',
           'ROBOT_LAB_DOMAIN_REGISTRY': str(tmp_path / 'domains.json')}
    env.update(extra)
    return env


def _notebook_domain(env: dict[str, str]) -> int:
    """The domain a notebook's setup() picks for this user (no ROS_DOMAIN_ID set)."""
    out = subprocess.run(
        [str(VENV / 'bin' / 'python'), '-c',
         'from robot_lab.grading.course import _domain; print(_domain("00_welcome"))'],
        env=env, capture_output=True, text=True, timeout=60, check=True)
    return int(out.stdout.strip())


def test_terminal_rcfile_makes_a_ros_shell(tmp_path: Path) -> None:
    course = tmp_path / 'course'
    course.mkdir()
    env = _clean_env(tmp_path, ROBOT_LAB_VENV=str(VENV))
    probe = ('echo "ros2=$(command -v ros2)"; echo "colcon=$(command -v colcon)"; '
             'echo "pwd=$PWD"; echo "domain=$ROS_DOMAIN_ID"; '
             'echo "range=$ROS_AUTOMATIC_DISCOVERY_RANGE"; echo "ws=$ROBOT_LAB_WORKSPACE"')
    shell = subprocess.run(['/bin/bash', '--rcfile', str(RCFILE), '-i', '-c', probe],
                           cwd=course, env=env, capture_output=True, text=True, timeout=60)
    assert shell.returncode == 0, shell.stderr
    seen = dict(line.split('=', 1) for line in shell.stdout.splitlines() if '=' in line)
    assert seen['ros2'] == str(VENV / 'bin' / 'ros2'), shell.stdout
    assert seen['colcon'] == str(VENV / 'bin' / 'colcon'), shell.stdout
    assert Path(seen['pwd']).resolve() == course.resolve()
    assert seen['range'] == 'LOCALHOST'
    assert seen['ws'] == f'{env["HOME"]}/robot_lab_ws'
    # The same domain the student's notebooks use, so `ros2 node list` here sees them.
    assert seen['domain'].isdigit(), shell.stdout
    assert int(seen['domain']) == _notebook_domain(env)
    assert 'ROS 2 Jazzy terminal (robot_lab)' in shell.stdout
    # The build the notebooks teach: a plain `colcon build` would undo --symlink-install.
    assert 'colcon build --symlink-install && source install/setup.bash' in shell.stdout


def test_terminal_keeps_a_domain_the_student_set(tmp_path: Path) -> None:
    env = _clean_env(tmp_path, ROBOT_LAB_VENV=str(VENV), ROS_DOMAIN_ID='42',
                     ROBOT_LAB_QUIET='1')
    shell = subprocess.run(['/bin/bash', '--rcfile', str(RCFILE), '-i', '-c',
                            'echo "domain=$ROS_DOMAIN_ID"'],
                           env=env, capture_output=True, text=True, timeout=60)
    assert shell.stdout.strip().splitlines()[-1] == 'domain=42'


def test_terminal_builds_and_sources_a_workspace(tmp_path: Path) -> None:
    """The lab's cycle in that terminal: pkg create, colcon build, source, find the package."""
    workspace = tmp_path / 'ws'
    (workspace / 'src').mkdir(parents=True)
    env = _clean_env(tmp_path, ROBOT_LAB_VENV=str(VENV), ROBOT_LAB_QUIET='1',
                     ROBOT_LAB_WORKSPACE=str(workspace))
    cycle = ('cd "$ROBOT_LAB_WORKSPACE/src" && ros2 pkg create --build-type ament_python '
             '--node-name hello --maintainer-name t --maintainer-email t@example.com bench_pkg '
             '>/dev/null && cd .. && colcon build >/dev/null && source install/setup.bash && '
             'ros2 pkg executables bench_pkg')
    shell = subprocess.run(['/bin/bash', '--rcfile', str(RCFILE), '-i', '-c', cycle],
                           env=env, capture_output=True, text=True, timeout=300)
    assert shell.returncode == 0, shell.stdout + shell.stderr
    assert shell.stdout.strip().splitlines()[-1] == 'bench_pkg hello', shell.stdout


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        port: int = sock.getsockname()[1]
        return port


def _wait_for_server(url: str, proc: subprocess.Popen[bytes], timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            out = proc.stdout.read().decode(errors='replace') if proc.stdout else ''
            pytest.fail(f'jupyter server exited with {proc.returncode}:\n{out[-2000:]}')
        try:
            with urllib.request.urlopen(url, timeout=2) as reply:
                if reply.status == 200:
                    return
        except (urllib.error.URLError, ConnectionError, TimeoutError):
            time.sleep(0.2)
    pytest.fail(f'jupyter server did not answer {url} within {timeout:g} s')


async def _terminal_says(ws_url: str, command: str, pattern: str, timeout: float) -> str:
    from tornado.websocket import websocket_connect

    conn = await websocket_connect(ws_url)
    try:
        conn.write_message(json.dumps(['stdin', command + '\r']))
        seen = ''
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            message = await asyncio.wait_for(conn.read_message(), deadline - time.monotonic())
            if message is None:
                break
            kind, *rest = json.loads(message)
            if kind == 'stdout':
                seen += str(rest[0])
                found = re.search(pattern, seen)
                if found:
                    return found.group(0)
        raise AssertionError(f'terminal never printed {pattern!r}; it printed:\n{seen[-2000:]}')
    finally:
        conn.close()


def _kit_home(tmp_path: Path) -> tuple[dict[str, str], Path, Path]:
    """A scratch home and a venv that `./kit` sees as set up (links to the real one)."""
    venv = tmp_path / 'venv'
    (venv / 'bin').mkdir(parents=True)
    for exe in (VENV / 'bin').iterdir():
        (venv / 'bin' / exe.name).symlink_to(exe)
    (venv / 'pyvenv.cfg').write_bytes((VENV / 'pyvenv.cfg').read_bytes())
    want = hashlib.sha256((ROOT / 'setup.py').read_bytes() + (ROOT / 'package.xml').read_bytes())
    (venv / '.robot_lab-setup').write_text(want.hexdigest()[:16] + '\n')
    course, workspace = tmp_path / 'home' / 'robot_lab_course', tmp_path / 'home' / 'robot_lab_ws'
    return _clean_env(tmp_path, ROBOT_LAB_VENV=str(venv)), course, workspace


def _get(url: str) -> object:
    with urllib.request.urlopen(url, timeout=30) as reply:
        return json.loads(reply.read())


def test_kit_lab_serves_the_course_copy_with_ros_terminals(tmp_path: Path) -> None:
    """`./kit lab`: JupyterLab rooted at the student's copy, its terminal a ROS terminal."""
    env, course, workspace = _kit_home(tmp_path)
    # This module's domain (the kit's warm graph daemon joins it too).
    env['ROS_DOMAIN_ID'] = os.environ['ROS_DOMAIN_ID']
    env.update(JUPYTER_CONFIG_DIR=str(tmp_path / 'jupyter_config'),
               JUPYTER_DATA_DIR=str(tmp_path / 'jupyter_data'),
               JUPYTER_RUNTIME_DIR=str(tmp_path / 'jupyter_runtime'))
    port, token = _free_port(), 'robot-lab-bench-test'
    lab = spawn([str(ROOT / 'kit'), 'lab', '--no-browser', f'--ServerApp.port={port}',
                 '--ServerApp.port_retries=0', f'--IdentityProvider.token={token}'],
                env=env, cwd=ROOT)
    try:
        base = f'http://127.0.0.1:{port}'
        _wait_for_server(f'{base}/api/status?token={token}', lab)
        root = _get(f'{base}/api/contents?token={token}')
        assert isinstance(root, dict)
        names = {item['name'] for item in root['content']}
        assert {'notebooks', 'exercises', 'robot_lab_ws'} <= names, names
        assert _get(f'{base}/api/contents/robot_lab_ws?token={token}'), 'workspace unreachable'
        # Released copies open trusted: the server finds the release's signature.
        model = _get(f'{base}/api/contents/notebooks/01_create_package.ipynb?token={token}')
        assert isinstance(model, dict)
        code = [c for c in model['content']['cells'] if c['cell_type'] == 'code']
        assert code and all(c['metadata'].get('trusted') for c in code), 'not trusted'
        request = urllib.request.Request(f'{base}/api/terminals?token={token}', method='POST',
                                         data=b'{}', headers={'Content-Type': 'application/json'})
        with urllib.request.urlopen(request, timeout=30) as reply:
            name = json.loads(reply.read())['name']
        said = asyncio.run(_terminal_says(
            f'ws://127.0.0.1:{port}/terminals/websocket/{name}?token={token}',
            'echo "RL|$(command -v ros2)|$PWD|$ROS_DOMAIN_ID|$ROBOT_LAB_WORKSPACE|END"',
            r'RL\|/[^|\s]*\|/[^|\s]*\|\d+\|/[^|\s]*\|END', timeout=60))
        _, ros2, cwd, domain, ws, _ = said.split('|')
        # ros2 from the kit's venv, although the server's PATH had none: the rcfile put it there.
        assert Path(ros2).resolve() == (VENV / 'bin' / 'ros2').resolve()
        assert Path(cwd).resolve() == course.resolve()  # not the repository the kit ran from
        assert domain == env['ROS_DOMAIN_ID']
        assert Path(ws) == workspace
    finally:
        stop(lab, sigint_timeout=0)
    # The copy is the released one (that a re-release keeps a student's changes is
    # robot-lab course release's own test).
    package = (course / 'notebooks' / '01_create_package.ipynb').read_text()
    assert 'raise NotImplementedError()' in package and 'BEGIN SOLUTION' not in package
    assert (course / 'exercises' / 'ex01_create_package.ipynb').is_file()


# --- the student's Lab: nbgrader's instructor tools hidden, on for an instructor -----------

INSTRUCTOR_PLUGINS = {'@jupyter/nbgrader:menu', '@jupyter/nbgrader:create-assignment',
                      '@jupyter/nbgrader:formgrader', '@jupyter/nbgrader:assignment-list',
                      '@jupyter/nbgrader:course-list'}
_PAGE_CONFIG = re.compile(
    r'<script id="jupyter-config-data" type="application/json">(.*?)</script>', re.S)
# A log line at warning level or worse, from the server or from nbgrader's own logger.
_LOG_TROUBLE = re.compile(r'^\[(?:W|E|C) [^]]*\].*|^\[NbGrader \| (?:WARNING|ERROR|CRITICAL)\].*',
                          re.M)


def _server_trouble(log: str) -> list[str]:
    """The first line of each log record from nbgrader at warning level or worse, and of
    each error record at all, but a request the test's Chromium left unanswered when it
    closed (tornado: `StreamClosedError`, the server answering a client that is gone)."""
    records = re.split(r'\n(?=\[)', log)
    return [record.splitlines()[0] for record in records
            if _LOG_TROUBLE.match(record)
            and ('nbgrader' in record.splitlines()[0].lower() or record.startswith('[E '))
            and 'tornado.iostream.StreamClosedError' not in record]


def _status(url: str) -> int:
    try:
        with urllib.request.urlopen(url, timeout=30) as reply:
            return int(reply.status)
    except urllib.error.HTTPError as err:
        return int(err.code)


def _lab_page(base: str, token: str, shots: Path) -> tuple[list[str], list[str]]:
    """The menus and side-panel tabs a real Chromium shows on the Lab page."""
    with headless_chromium() as browser:
        page = browser.new_page()
        page.goto(f'{base}/lab?token={token}')
        # The status bar comes up once every plugin has been activated (or refused).
        page.wait_for_selector('#jp-main-statusbar .jp-StatusBar-Item', timeout=120_000)
        page.wait_for_selector('.lm-MenuBar-itemLabel', timeout=120_000)
        menus = page.locator('.lm-MenuBar-itemLabel').all_inner_texts()
        tabs = page.locator('.lm-TabBar-tab').evaluate_all(
            'tabs => tabs.map(t => t.getAttribute("title") || t.innerText)')
        page.screenshot(path=str(shots))
    return [str(m) for m in menus], [str(t) for t in tabs]


@pytest.mark.browser
@pytest.mark.parametrize('who', ['student', 'instructor'])
def test_students_lab_hides_nbgrader_instructor_tools(tmp_path: Path, who: str) -> None:
    """`./kit lab` shows a student no nbgrader menu, Create Assignment, Formgrader or
    Assignment List, and logs no nbgrader trouble; `./kit lab --instructor` shows them."""
    env, _course, _workspace = _kit_home(tmp_path)
    env['ROS_DOMAIN_ID'] = os.environ['ROS_DOMAIN_ID']
    env.update(JUPYTER_CONFIG_DIR=str(tmp_path / 'jupyter_config'),
               JUPYTER_DATA_DIR=str(tmp_path / 'jupyter_data'),
               JUPYTER_RUNTIME_DIR=str(tmp_path / 'jupyter_runtime'))
    env.pop('ROBOT_LAB_INSTRUCTOR', None)
    port, token = _free_port(), 'robot-lab-student-test'
    switch = ['--instructor'] if who == 'instructor' else []
    log_path = tmp_path / 'lab.log'
    with log_path.open('wb') as log:
        lab = spawn([str(ROOT / 'kit'), 'lab', *switch, '--no-browser',
                     f'--ServerApp.port={port}', '--ServerApp.port_retries=0',
                     f'--IdentityProvider.token={token}'],
                    env=env, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT)
        try:
            base = f'http://127.0.0.1:{port}'
            deadline = time.monotonic() + 120
            while _status_or_none(f'{base}/api/status?token={token}') != 200:
                assert lab.poll() is None, log_path.read_text()[-3000:]
                assert time.monotonic() < deadline, 'JupyterLab did not answer in 120 s'
                time.sleep(0.2)  # polling the server's own readiness answer
            with urllib.request.urlopen(f'{base}/lab?token={token}', timeout=30) as reply:
                page = reply.read().decode()
            found = _PAGE_CONFIG.search(page)
            assert found, 'no page config in the Lab page'
            config = json.loads(found.group(1))
            disabled = set(config['disabledExtensions'])
            assert config['news'] == {'disabled': True}  # no news feed fetched
            notification = _get(f'{base}/lab/api/settings/@jupyterlab/apputils-extension:'
                                f'notification?token={token}')
            assert isinstance(notification, dict)
            # ...and JupyterLab does not ask "get notified about official Jupyter news?"
            assert notification['schema']['properties']['fetchNews']['default'] == 'false'
            assert '@jupyter/nbgrader:validate-assignment' not in disabled  # Validate stays
            import nbgrader  # type: ignore[import-untyped]

            version = f'{base}/nbgrader_version?version={nbgrader.__version__}&token={token}'
            assert _status(version) == 200  # what Validate asks before it validates
            menus, tabs = _lab_page(base, token, tmp_path / f'{who}.png')
            started = log_path.read_text()  # the start and the page's own requests
            formgrader = _status(f'{base}/formgrader?token={token}')
            assignments = _status(f'{base}/assignments?course_id=c&token={token}')
        finally:
            stop(lab, sigint_timeout=0)
    if who == 'student':
        assert disabled >= INSTRUCTOR_PLUGINS, INSTRUCTOR_PLUGINS - disabled
        assert 'Nbgrader' not in menus, menus
        assert not [t for t in tabs if 'Assignment' in t or 'nbgrader' in t.lower()], tabs
        assert (formgrader, assignments) == (404, 404)  # their server extensions are off
        # Nothing at warning level or worse from nbgrader, nothing at error level at all.
        assert _server_trouble(started) == []
    else:
        assert not INSTRUCTOR_PLUGINS & disabled
        assert 'Nbgrader' in menus, menus
        assert 'Nbgrader Create Assignment' in tabs, tabs
        assert formgrader == 200


def _status_or_none(url: str) -> int | None:
    try:
        return _status(url)
    except (urllib.error.URLError, ConnectionError, TimeoutError):
        return None


# --- ./kit start: a student's install, a short demo summary ---------------------------------

TEST_TOOLS = {'pytest', 'pytest-timeout', 'pytest-xdist', 'nbval', 'ruff', 'mypy', 'playwright',
              'jupyterhub', 'jupyter-repo2docker', 'bqplot'}


def test_student_install_has_no_test_tools() -> None:
    """`./kit start`/`setup` install the `kit` extra; the test tools come with `./kit test`."""
    from importlib.metadata import requires

    extras: dict[str, set[str]] = {}
    for requirement in requires('robot_lab') or []:
        found = re.match(r'([A-Za-z0-9_.\[\]-]+).*extra == "(\w+)"', requirement)
        if found:
            name = re.sub(r'\[.*\]', '', found.group(1)).lower().replace('_', '-')
            extras.setdefault(found.group(2), set()).add(name)
    assert not extras['kit'] & TEST_TOOLS, extras['kit'] & TEST_TOOLS
    assert extras['test'] >= TEST_TOOLS | extras['kit']
    assert {'nbgrader', 'jupyterlab', 'colcon-core', 'ros-jazzy-rclpy'} <= extras['kit']
    kit = (ROOT / 'kit').read_text()
    assert re.search(r'^  test\)\n    setup test$', kit, re.M), 'kit test adds the test tools'
    assert re.search(r'^  lint\)\n    setup test$', kit, re.M), 'kit lint adds the test tools'
    assert re.search(r'^  start\)\n    setup$', kit, re.M), 'kit start installs the kit only'
    assert './kit setup --test' in (ROOT / '.ci' / 'run').read_text()


def test_kit_start_summarises_the_demo_and_logs_it_in_full(tmp_path: Path) -> None:
    env, _course, _workspace = _kit_home(tmp_path)
    env['ROS_DOMAIN_ID'] = os.environ['ROS_DOMAIN_ID']
    start = subprocess.run([str(ROOT / 'kit'), 'start', '--no-lab'], env=env, cwd=ROOT,
                           capture_output=True, text=True, timeout=300)
    assert start.returncode == 0, start.stdout + start.stderr
    shown = (start.stdout + start.stderr).splitlines()
    log = Path(env['HOME']) / '.ros' / 'log' / 'robot_lab_demo.log'
    assert shown[-1].endswith('full demo log: ~/.ros/log/robot_lab_demo.log'), shown
    assert len(shown) <= 8, '\n'.join(shown)
    assert 'nodes seen: /controller, /robot, /sensor' in start.stdout
    full = log.read_text()
    # Every node's own lines are in the file, not on the student's terminal.
    assert re.search(r'\[robot\]: Status: OK', full) and 'Status: OK' not in start.stdout
    assert len(full.splitlines()) > 3 * len(shown)
