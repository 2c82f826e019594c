"""Every way a class gets the course gives students the released copy, never the source.

- a plain JupyterHub: docs/deploy.md's jupyterhub_config.py, loaded by JupyterHub's own
  config loader on a fresh Config (tests/test_deploy.py also runs a hub with it);
- The Littlest JupyterHub: the plugin's hooks called as TLJH's jupyterhub_config.py and
  its user creation call them (pluggy, hook specifications by TLJH's names and arguments);
- the repo2docker image (Binder, Zero to JupyterHub): binder/student-course as postBuild
  runs it, the URL Binder students open, and the z2jh postStart hook at two starts;
- nbgitpuller: the published repository docs/deploy.md makes, as a first pull clones it.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from conftest import BIN, REPO
from student_copy import answers_in, student_notebooks
from unixusers import can_create_users, unix_users

DEPLOY = (REPO / 'docs' / 'deploy.md').read_text()


def _block(language: str, containing: str) -> str:
    blocks = re.findall(rf'```{language}\n(.*?)```', DEPLOY, re.S)
    [found] = [b for b in blocks if containing in b]
    return str(found)


def _env(tmp: Path, **extra: str) -> dict[str, str]:
    env = {'PATH': f'{BIN}:/usr/bin:/bin', 'LANG': 'C.UTF-8', 'HOME': str(tmp / 'admin'),
           'ROBOT_LAB_SOURCE': str(REPO), 'ROBOT_LAB_PYTHON': str(BIN / 'python'),
           'ROBOT_LAB_DOMAIN_REGISTRY': str(tmp / 'registry' / 'domains.json'),
           'ROBOT_LAB_PUBLISHED': str(tmp / 'published')}
    env.update(extra)
    return env


LOAD = """
import json, sys
from jupyterhub.app import JupyterHub
from jupyterhub.spawner import Spawner
app = JupyterHub()
app.load_config_file(sys.argv[1])
spawner = Spawner(config=app.config)
print(json.dumps({'environment': sorted(spawner.environment),
                  'hook': callable(spawner.pre_spawn_hook),
                  'url': spawner.default_url,
                  'authenticator': str(app.config.JupyterHub.authenticator_class)}))
"""


def test_documented_hub_config_loads_through_jupyterhubs_loader(tmp_path: Path) -> None:
    config = tmp_path / 'jupyterhub_config.py'
    config.write_text(_block('python', 'configure_hub(c)'))
    (tmp_path / 'admin').mkdir()
    done = subprocess.run([str(BIN / 'python'), '-c', LOAD, str(config)], env=_env(tmp_path),
                          cwd=tmp_path, capture_output=True, text=True, timeout=300,
                          check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    loaded = json.loads(done.stdout.splitlines()[-1])
    assert {'ROS_DOMAIN_ID', 'ROBOT_LAB_DOMAIN_REGISTRY'} <= set(loaded['environment'])
    assert loaded['hook'] and loaded['url'].endswith('robot_lab_course/notebooks/00_welcome'
                                                     '.ipynb')
    assert loaded['authenticator'] == 'pam'
    published = tmp_path / 'published'  # what every student's copy is released from
    assert len(student_notebooks(published)) >= 15
    assert answers_in(published) == []


SPECS = '''"""TLJH's hook specifications (tljh/hooks.py): the names and arguments TLJH calls."""
import pluggy

hookspec = pluggy.HookspecMarker('tljh')

@hookspec
def tljh_extra_user_pip_packages(): ...
@hookspec
def tljh_extra_hub_pip_packages(): ...
@hookspec
def tljh_custom_jupyterhub_config(c): ...
@hookspec
def tljh_post_install(): ...
@hookspec
def tljh_new_user_create(username): ...
'''

# As TLJH's jupyterhub_config.py: its own settings, then every plugin's config hook.
TLJH_CONFIG = """
import sys
import pluggy
sys.path[:0] = [{specs!r}, {plugin!r}]
import tljh_hookspecs, tljh_robot_lab
c.JupyterHub.spawner_class = 'localprocess'
c.SystemdSpawner.unit_name_template = 'jupyter-{{USERNAME}}'
pm = pluggy.PluginManager('tljh')
pm.add_hookspecs(tljh_hookspecs)
pm.register(tljh_robot_lab)
pm.hook.tljh_custom_jupyterhub_config(c=c)
"""

# Then what TLJH does for a new hub user: create `jupyter-<name>`, call tljh_new_user_create
# with that Unix name; at every later start JupyterHub calls the pre-spawn hook.
SPAWN = """
import json, sys, types
from pathlib import Path
from jupyterhub.app import JupyterHub
from jupyterhub.spawner import Spawner
app = JupyterHub()
app.load_config_file(sys.argv[1])
import tljh_robot_lab
import pluggy, tljh_hookspecs
pm = pluggy.PluginManager('tljh')
pm.add_hookspecs(tljh_hookspecs)
pm.register(tljh_robot_lab)
hub_name, unix_name = sys.argv[2], sys.argv[3]
pm.hook.tljh_new_user_create(username=unix_name)
home = Path(sys.argv[4]) / 'robot_lab_course'
first = sorted(str(p.relative_to(home)) for p in home.rglob('*.ipynb'))
edited = home / 'exercises' / 'ex04_parameters.ipynb'
edited.write_text(edited.read_text().replace('raise NotImplementedError()', 'x = 1', 1))
(home / 'notebooks' / '00_welcome.ipynb').unlink()
spawner = Spawner(config=app.config)
fake = types.SimpleNamespace(user=types.SimpleNamespace(name=hub_name),
                             environment={'ROBOT_LAB_USER_DOMAINS': '93-101'})
spawner.pre_spawn_hook(fake)
env = {k: (v(fake) if callable(v) else v) for k, v in spawner.environment.items()}
print(json.dumps({'first': first, 'kept': 'x = 1' in edited.read_text(),
                  'back': (home / 'notebooks' / '00_welcome.ipynb').exists(),
                  'domain': env['ROS_DOMAIN_ID']}))
"""


def test_tljh_hooks_give_each_new_user_the_released_course(tmp_path: Path) -> None:
    why = can_create_users()
    if why:
        pytest.skip(why)
    with unix_users() as users:
        work = users.root / 'tljh'
        work.mkdir()
        (work / 'tljh_hookspecs.py').write_text(SPECS)
        config = work / 'jupyterhub_config.py'
        config.write_text(TLJH_CONFIG.format(specs=str(work),
                                             plugin=str(REPO / 'deploy' / 'tljh')))
        student = users.add('s', template='jupyter-{}')
        hub_name = student.name.removeprefix('jupyter-')
        env = _env(users.root)
        env['PYTHONPATH'] = f'{work}:{REPO / "deploy" / "tljh"}'
        done = subprocess.run(users.command(None, [
            str(BIN / 'python'), '-c', SPAWN, str(config), hub_name, student.name,
            str(student.home)]), env=env, cwd=work, capture_output=True, text=True,
            timeout=600, check=False)
        assert done.returncode == 0, done.stderr[-3000:]
        seen = json.loads(done.stdout.splitlines()[-1])
        home = student.home / 'robot_lab_course'
        assert seen['first'] == student_notebooks(users.root / 'published')
        assert len(seen['first']) >= 15
        assert seen['kept'] and seen['back']  # a second start: edits kept, losses restored
        assert all(p.stat().st_uid == student.uid for p in home.rglob('*'))
        assert answers_in(home) == []
        registry = json.loads((users.root / 'registry' / 'domains.json').read_text())
        assert registry['users'][str(student.uid)]['domain'] == int(seen['domain'])


@pytest.fixture(scope='module')
def image_tree(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The repository as repo2docker copies it (tracked files), after postBuild's last step."""
    root = tmp_path_factory.mktemp('image') / 'srv_robot_lab'
    files = subprocess.run(['git', 'ls-files'], cwd=REPO, capture_output=True, text=True,
                           check=True).stdout.splitlines()
    for rel in files:
        if (REPO / rel).is_file():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(REPO / rel, root / rel)
    (root / '.git').mkdir()
    post_build = (REPO / 'binder' / 'postBuild').read_text()
    assert post_build.rstrip().endswith('exec binder/student-course')
    env = {'PATH': f'{BIN}:/usr/bin:/bin', 'HOME': str(root), 'LANG': 'C.UTF-8',
           'JUPYTER_DATA_DIR': str(root / '.local' / 'share' / 'jupyter')}
    done = subprocess.run(['binder/student-course'], cwd=root, env=env, capture_output=True,
                          text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    return root


def test_the_image_holds_the_students_copy_and_no_answers(image_tree: Path) -> None:
    for gone in ('solutions', 'notebooks', 'tests', '.git'):
        assert not (image_tree / gone).exists(), gone
    assert len(student_notebooks(image_tree / 'robot_lab_course')) >= 15
    assert answers_in(image_tree) == []  # anywhere in the image's course folder


def test_binder_students_open_the_released_copy(image_tree: Path) -> None:
    [url] = re.findall(r'https://mybinder\.org/\S+', DEPLOY)
    [path] = re.findall(r'urlpath=lab/tree/(\S+)', url)
    assert path.startswith('robot_lab_course/')
    assert (image_tree / path).is_file()  # Binder's home is the repository folder


def test_z2jh_post_start_releases_the_copy_and_keeps_edits(image_tree: Path,
                                                          tmp_path: Path) -> None:
    values = yaml.safe_load((REPO / 'deploy' / 'z2jh' / 'config.yaml').read_text())
    single = values['singleuser']
    command = single['lifecycleHooks']['postStart']['exec']['command']
    published = single['extraEnv']['ROBOT_LAB_PUBLISHED']
    assert published == '/srv/robot_lab/robot_lab_course'  # --target-repo-dir + student-course
    home = tmp_path / 'jovyan'
    home.mkdir()
    env = {'PATH': f'{BIN}:/usr/bin:/bin', 'HOME': str(home), 'LANG': 'C.UTF-8',
           'ROBOT_LAB_PUBLISHED': str(image_tree / 'robot_lab_course')}

    def start() -> None:
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=600,
                              check=False)
        assert done.returncode == 0, done.stderr
    start()
    course = home / 'robot_lab_course'
    assert student_notebooks(course) == student_notebooks(image_tree / 'robot_lab_course')
    assert single['defaultUrl'] == '/lab/tree/robot_lab_course/notebooks/00_welcome.ipynb'
    assert (home / single['defaultUrl'].removeprefix('/lab/tree/')).is_file()
    assert answers_in(home) == []
    edited = course / 'exercises' / 'ex02_write_nodes.ipynb'
    edited.write_text(edited.read_text().replace('raise NotImplementedError()', 'y = 2', 1))
    start()
    assert 'y = 2' in edited.read_text()  # the student's change survives the next start


def test_z2jh_values_name_a_real_authenticator() -> None:
    values = yaml.safe_load((REPO / 'deploy' / 'z2jh' / 'config.yaml').read_text())
    hub = values['hub']['config']
    assert hub['JupyterHub']['authenticator_class'] == 'github'
    assert hub['GitHubOAuthenticator']['allowed_organizations']
    assert 'client_secret' not in json.dumps(hub)  # the instructor's, passed at install
    trial = REPO / 'deploy' / 'z2jh' / 'try-it-dummy.yaml'
    text = trial.read_text()
    assert text.startswith('# FOR A FIRST LOOK ONLY')
    assert yaml.safe_load(text)['hub']['config']['JupyterHub']['authenticator_class'] == 'dummy'


def test_nbgitpuller_recipe_publishes_only_the_released_copy(tmp_path: Path) -> None:
    recipe = _block('console', 'git -C robot_lab_course init')
    commands = [line[2:] for line in recipe.splitlines() if line.startswith('$ ')]
    env = {'PATH': f'{BIN}:/usr/bin:/bin', 'HOME': str(tmp_path), 'LANG': 'C.UTF-8',
           'GIT_AUTHOR_NAME': 'instructor', 'GIT_AUTHOR_EMAIL': 'i@example.org',
           'GIT_COMMITTER_NAME': 'instructor', 'GIT_COMMITTER_EMAIL': 'i@example.org',
           'ROBOT_LAB_SOURCE': str(REPO)}
    script = '\n'.join(c for c in commands if not c.startswith('git push'))
    done = subprocess.run(['bash', '-euc', script], cwd=tmp_path, env=env, text=True,
                          capture_output=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    [repo] = [p.parent for p in tmp_path.rglob('.git') if p.is_dir()]
    # nbgitpuller's first pull is a clone of the repository's default branch.
    clone = tmp_path / 'student' / 'robot_lab_course'
    subprocess.run(['git', 'clone', '-q', str(repo), str(clone)], check=True, env=env)
    assert len(student_notebooks(clone)) >= 15
    assert answers_in(clone) == []


if __name__ == '__main__':  # pragma: no cover
    sys.exit(pytest.main([__file__, '-q', *os.environ.get('PYTEST_ARGS', '').split()]))
