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
