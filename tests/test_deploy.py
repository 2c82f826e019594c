"""Deployments (docs/deploy.md): the repo2docker image of binder/, and a JupyterHub that
serves every student their own copy of the course in their own ROS domain.

The hub test runs a real JupyterHub (dummy authenticator, local process spawner) on
127.0.0.1 as root, with two temporary Unix users, and asks each user's kernel which
domain it is in. There is no configurable-http-proxy (Node) here: the hub runs with a
proxy that only records routes, and the test talks to the hub's API and to each
single-user server directly.
"""

from __future__ import annotations

import json
import shutil
import socket
import subprocess
import sys
import time
import uuid
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest
from conftest import BIN, REPO, Proc
from student_copy import answers_in, student_notebooks
from unixusers import UnixUsers, can_create_users, unix_users

REPO2DOCKER = BIN / 'jupyter-repo2docker'
TOKEN = uuid.uuid4().hex


def _repo2docker(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(REPO2DOCKER), '--user-id', '1000', '--user-name', 'jovyan',
                           '--target-repo-dir',
                           '/srv/robot_lab', *args, str(REPO)], capture_output=True,
                          text=True, timeout=600, check=False)


@pytest.mark.skipif(not REPO2DOCKER.exists(), reason='jupyter-repo2docker is not installed '
                    "(pip install 'robot_lab[test]')")
def test_repo2docker_builds_the_course_image_from_binder() -> None:
    result = _repo2docker('--no-build', '--debug')
    assert result.returncode == 0, result.stderr[-2000:]
    dockerfile = result.stdout + result.stderr
    assert 'conda environment for python=3.11' in dockerfile  # binder/runtime.txt
    assert 'RUN ./binder/postBuild' in dockerfile
    assert 'ARG REPO_DIR=' in dockerfile  # the course lands in /srv/robot_lab (z2jh)
    post_build = (REPO / 'binder' / 'postBuild').read_text()
    assert "pip install --no-cache-dir '.[kit]'" in post_build
    assert '--name robot_lab' in post_build
    notebook = json.loads((REPO / 'notebooks' / '00_welcome.ipynb').read_text())
    assert notebook['metadata']['kernelspec']['name'] == 'robot_lab'  # what postBuild adds


def _docker_daemon() -> str | None:
    if shutil.which('docker') is None:
        return 'docker is not installed'
    info = subprocess.run(['docker', 'info'], capture_output=True, text=True, check=False)
    if info.returncode != 0:
        return 'no Docker daemon: ' + (info.stderr.strip().splitlines() or ['?'])[-1]
    return None


def test_repo2docker_real_build() -> None:
    why = _docker_daemon()
    if why:
        pytest.skip(why)
    result = _repo2docker('--no-run', '--image-name', 'robot-lab-test')
    assert result.returncode == 0, result.stderr[-3000:]


# --- a JupyterHub with two students ------------------------------------------------------

HUB_CONFIG = """
import sys
sys.path.insert(0, {plugin!r})
from jupyterhub.proxy import Proxy
from tljh_robot_lab import configure_hub

class RecordingProxy(Proxy):
    '''No proxy process: routes are only recorded (the test talks to servers directly).'''
    should_start = False
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.table = {{}}
    async def add_route(self, routespec, target, data):
        self.table[routespec] = {{'routespec': routespec, 'target': target, 'data': data}}
    async def delete_route(self, routespec):
        self.table.pop(routespec, None)
    async def get_all_routes(self):
        return dict(self.table)

PORTS = {ports!r}

def set_port(spawner):
    spawner.port = PORTS[spawner.user.name]

c.JupyterHub.bind_url = 'http://127.0.0.1:{proxy_port}'
c.JupyterHub.hub_bind_url = 'http://127.0.0.1:{hub_port}'
c.JupyterHub.proxy_class = RecordingProxy
c.JupyterHub.db_url = 'sqlite:///{state}/jupyterhub.sqlite'
c.JupyterHub.cookie_secret_file = '{state}/cookie_secret'
c.JupyterHub.authenticator_class = 'dummy'
c.Authenticator.allowed_users = set(PORTS)
c.JupyterHub.spawner_class = 'localprocess'
c.Spawner.cmd = [{singleuser!r}]
c.Spawner.ip = '127.0.0.1'
c.Spawner.start_timeout = 120
c.Spawner.http_timeout = 120
c.Spawner.pre_spawn_hook = set_port  # configure_hub keeps it and adds the course's
# jupyter-server answers SIGINT by asking for confirmation (10 s); SIGTERM stops it at once.
c.LocalProcessSpawner.interrupt_timeout = 1
configure_hub(c)  # on a Config where nothing of the Spawner's environment was set
c.Spawner.environment.update({{'ROBOT_LAB_USER_DOMAINS': '93-101'}})
c.JupyterHub.services = [{{'name': 'course-test', 'api_token': {token!r}}}]
c.JupyterHub.load_roles = [{{
    'name': 'course-test', 'services': ['course-test'],
    'scopes': ['admin:users', 'admin:servers', 'access:servers', 'list:users'],
}}]
"""

KERNEL_CODE = (
    'import os\n'
    'hub = os.environ.get("ROS_DOMAIN_ID")  # what a terminal\'s plain python would use\n'
    'import robot_lab\n'
    'from robot_lab.domain import resolve\n'
    'print("DOMAIN", robot_lab.session().domain_id, resolve().source, os.getuid(), hub)\n'
)


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        port: int = sock.getsockname()[1]
        return port


def _api(url: str, method: str = 'GET', body: Any = None) -> tuple[int, Any]:
    from urllib.error import HTTPError
    from urllib.request import Request, urlopen

    data = None if body is None else json.dumps(body).encode()
    request = Request(url, data=data, method=method,
                      headers={'Authorization': f'token {TOKEN}'})
    try:
        with urlopen(request, timeout=30) as response:
            text = response.read().decode()
            return response.status, json.loads(text) if text else None
    except HTTPError as err:
        return err.code, err.read().decode()


def _plugin_env(root: Path, registry: Path) -> dict[str, str]:
    """The plugin's paths for a test: this checkout, a temporary registry and published copy."""
    return {'ROBOT_LAB_SOURCE': str(REPO), 'ROBOT_LAB_DOMAIN_REGISTRY': str(registry),
            'ROBOT_LAB_PUBLISHED': str(root / 'published'),
            'ROBOT_LAB_PYTHON': str(BIN / 'python')}


class Hub:
    def __init__(self, users: UnixUsers, proc: Proc, hub_port: int,
                 ports: dict[str, int]) -> None:
        self.users, self.proc, self.ports = users, proc, ports
        self.published = users.root / 'published'
        self.api = f'http://127.0.0.1:{hub_port}/hub/api'

    def wait_ready(self, name: str, timeout: float = 120) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            status, model = _api(f'{self.api}/users/{name}')
            if status == 200 and model['servers'].get('', {}).get('ready'):
                return
            time.sleep(0.2)
        raise AssertionError(f'{name}: server not ready\n' + self.proc.output[-3000:])

    def server(self, name: str) -> str:
        return f'http://127.0.0.1:{self.ports[name]}/user/{name}'


@pytest.fixture(scope='module')
def hub() -> Iterator[Hub]:
    why = can_create_users()
    if why:
        pytest.skip(why)
    with unix_users() as users:
        state = users.root / 'hub'
        state.mkdir()
        registry = users.root / 'registry' / 'domains.json'
        a, b = users.add('a'), users.add('b')
        ports = {a.name: _free_port(), b.name: _free_port()}
        hub_port = _free_port()
        config = state / 'jupyterhub_config.py'
        config.write_text(HUB_CONFIG.format(
            plugin=str(REPO / 'deploy' / 'tljh'), ports=ports,
            proxy_port=_free_port(), hub_port=hub_port, state=state,
            singleuser=str(BIN / 'jupyterhub-singleuser'), token=TOKEN))
        proc = Proc(users.command(None, [str(BIN / 'jupyterhub'), '-f', str(config)]),
                    env={'PATH': f'{BIN}:/usr/bin:/bin', 'LANG': 'C.UTF-8',
                         'HOME': str(state), **_plugin_env(users.root, registry)}, cwd=state)
        try:
            proc.wait_for(r'JupyterHub is now running', timeout=60)
            yield Hub(users, proc, hub_port, ports)
        finally:
            for name in ports:
                _api(f'http://127.0.0.1:{hub_port}/hub/api/users/{name}/server', 'DELETE')
            proc.stop()


def _run_in_kernel(server: str, code: str) -> str:
    """Start a robot_lab kernel on a user's server, run `code`, return its stdout."""
    import asyncio

    from tornado.httpclient import HTTPRequest
    from tornado.websocket import websocket_connect

    status, kernel = _api(f'{server}/api/kernels', 'POST', {'name': 'robot_lab'})
    assert status == 201, kernel
    url = server.replace('http://', 'ws://') + f'/api/kernels/{kernel["id"]}/channels'

    async def execute() -> str:
        conn = await websocket_connect(HTTPRequest(
            url, headers={'Authorization': f'token {TOKEN}'}))
        msg_id = uuid.uuid4().hex
        await conn.write_message(json.dumps({
            'header': {'msg_id': msg_id, 'msg_type': 'execute_request', 'username': 'test',
                       'session': uuid.uuid4().hex, 'version': '5.3'},
            'parent_header': {}, 'metadata': {}, 'channel': 'shell', 'buffers': [],
            'content': {'code': code, 'silent': False, 'store_history': False,
                        'user_expressions': {}, 'allow_stdin': False},
        }))
        out = []
        while True:
            raw = await asyncio.wait_for(conn.read_message(), 90)
            assert raw is not None, 'kernel channel closed'
            msg = json.loads(raw)
            if msg['parent_header'].get('msg_id') != msg_id:
                continue
            kind = msg['msg_type']
            if kind == 'stream':
                out.append(msg['content']['text'])
            elif kind == 'error':
                raise AssertionError('\n'.join(msg['content']['traceback']))
            elif kind == 'status' and msg['content']['execution_state'] == 'idle':
                conn.close()
                return ''.join(out)

    try:
        return asyncio.run(execute())
    finally:
        _api(f'{server}/api/kernels/{kernel["id"]}', 'DELETE')


def test_hub_gives_each_student_their_course_and_domain(hub: Hub) -> None:
    names = list(hub.ports)
    for name in names:
        status, _ = _api(f'{hub.api}/users/{name}/server', 'POST')
        assert status in (201, 202), f'{status}\n' + hub.proc.output[-3000:]
    def student(name: str) -> tuple[int, str, int, str]:
        hub.wait_ready(name)
        status, listing = _api(f'{hub.server(name)}/api/contents/robot_lab_course/notebooks')
        assert status == 200, listing
        assert '00_welcome.ipynb' in {item['name'] for item in listing['content']}
        home = Path(hub.users.users[name[-1]].home) / 'robot_lab_course'
        assert home.stat().st_uid == hub.users.users[name[-1]].uid  # the student's copy
        assert all(p.stat().st_uid == home.stat().st_uid for p in home.rglob('*'))
        assert len(student_notebooks(home)) == len(student_notebooks(hub.published)) >= 15
        assert answers_in(home) == []  # released: no solution block, no answer line
        words = _run_in_kernel(hub.server(name), KERNEL_CODE).split()
        assert words[:1] == ['DOMAIN'], words
        return int(words[1]), words[2], int(words[3]), words[4]

    with ThreadPoolExecutor(len(names)) as pool:  # both students at once, as in a class
        seen = dict(zip(names, pool.map(student, names), strict=True))
    (da, sa, ua, ha), (db, sb, ub, hb) = seen.values()
    assert sa == sb == 'registry'  # no student set ROS_DOMAIN_ID: the registry chose
    assert (ha, hb) == (str(da), str(db))  # and the hub put it in the whole server's env
    assert da != db and {da, db} <= set(range(93, 102)), seen
    assert (ua, ub) == (hub.users.users['a'].uid, hub.users.users['b'].uid)


if __name__ == '__main__':  # pragma: no cover
    sys.exit(pytest.main([__file__, '-q']))
