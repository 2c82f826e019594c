"""robot_lab for a whole class on one JupyterHub host (a The Littlest JupyterHub plugin).

What a course host needs beyond `pip install`:
- the kit and its kernel in the users' environment (`tljh_extra_user_pip_packages`,
  `tljh_post_install`);
- one ROS domain registry for all users, read by the hub too, which sets each user's
  ROS_DOMAIN_ID for their whole server (terminals included). systemd gives each TLJH
  user server a private /tmp and /var/tmp (SystemdSpawner's isolate_tmp), where the
  default registry (/var/tmp/robot_lab/domains.json) would be private too and every
  student would get the same domain. The registry goes to /srv/robot_lab instead;
- the students' copy of the course, never its source (whose solutions/ and notebooks/
  hold the answers): the hub publishes `robot-lab course release` of the source once
  (/srv/robot_lab/course), and each student's ~/robot_lab_course is released from that
  copy, as the student, at every server start: new notebooks arrive, a notebook the
  student changed is never overwritten. (~/robot_lab_course, not ~/robot_lab, which would
  shadow the kit's package in a kernel started in the home folder.)

The functions below work for any JupyterHub too (`configure_hub`): deploy/jupyterhub_config.py
is a plain hub's configuration that uses them, and tests/test_deploy.py runs it.
"""

from __future__ import annotations

import os
import pwd
import subprocess
import sys
from pathlib import Path
from typing import Any

try:
    from pluggy import HookimplMarker
except ImportError:  # a plain JupyterHub: the tljh_* hooks are simply never called
    def hookimpl(function: Any) -> Any:
        return function
else:
    hookimpl = HookimplMarker('tljh')

# Where the course repository is checked out on the host (docs/deploy.md, step 1).
SOURCE = Path(os.environ.get('ROBOT_LAB_SOURCE', '/opt/robot_lab'))
# Shared by every user: outside /tmp and /var/tmp (private per user under systemd).
REGISTRY = Path(os.environ.get('ROBOT_LAB_DOMAIN_REGISTRY', '/srv/robot_lab/domains.json'))
# The released copy every student's copy is released from (no answers in it).
PUBLISHED = Path(os.environ.get('ROBOT_LAB_PUBLISHED', '/srv/robot_lab/course'))
COURSE_HOME = 'robot_lab_course'
USER_PYTHON = Path('/opt/tljh/user/bin/python')
TLJH_USERS = 'jupyter-{USERNAME}'  # TLJH's Unix name for a hub user


def kit_python() -> str:
    """The Python that has the kit: ROBOT_LAB_PYTHON, TLJH's user environment, or ours."""
    named = os.environ.get('ROBOT_LAB_PYTHON', '').strip()
    if named:
        return named
    return str(USER_PYTHON) if USER_PYTHON.exists() else sys.executable


def _release(dest: Path, course: Path, *, user: pwd.struct_passwd | None = None,
             sign: bool = True) -> None:
    """`robot-lab course release DEST --course COURSE`, as `user` when given."""
    cmd = [kit_python(), '-c', 'from robot_lab.cli import entry; entry()', 'course',
           'release', str(dest), '--course', str(course)]
    env = {'PATH': f'{Path(kit_python()).parent}:/usr/bin:/bin', 'LANG': 'C.UTF-8'}
    switch: dict[str, Any] = {}
    if user is not None:
        env.update(HOME=user.pw_dir, USER=user.pw_name, LOGNAME=user.pw_name)
        if os.geteuid() != user.pw_uid:
            switch = {'user': user.pw_uid, 'group': user.pw_gid, 'extra_groups': []}
    done = subprocess.run([*cmd, *([] if sign else ['--no-sign'])], env=env, cwd='/',
                          capture_output=True, text=True, timeout=600, check=False, **switch)
    if done.returncode != 0:
        said = (done.stderr.strip().splitlines() or [f'exit {done.returncode}'])[-1]
        raise RuntimeError(f'robot_lab: releasing the course into {dest} failed: {said}')


def prepare_registry(registry: Path = REGISTRY) -> None:
    """The registry's folder, writable by every user like /tmp (sticky)."""
    registry.parent.mkdir(parents=True, exist_ok=True)
    registry.parent.chmod(0o1777)


def publish_course(source: Path = SOURCE, published: Path = PUBLISHED) -> Path:
    """The students' copy of the course source, readable by every user: what their own
    copies are released from (so no student ever reads the source's answers)."""
    published.parent.mkdir(parents=True, exist_ok=True)
    _release(published, source, sign=False)
    for path in [published, *published.rglob('*')]:
        path.chmod(0o755 if path.is_dir() else 0o644)
    return published


def install_course(unix_user: str, published: Path = PUBLISHED) -> Path:
    """Release the published copy into the user's ~/robot_lab_course, as the user: new
    notebooks are added, their changes are kept, notebooks open trusted."""
    entry = pwd.getpwnam(unix_user)
    if not (published / '.robot_lab' / 'release.json').is_file():
        publish_course(published=published)
    target = Path(entry.pw_dir) / COURSE_HOME
    _release(target, published, user=entry)
    return target


def unix_name(spawner: Any, template: str | None = None) -> str:
    """The Unix user a spawner runs a hub user as (TLJH: `jupyter-<name>`)."""
    if template is None:
        template = str(getattr(spawner, 'username_template', '{USERNAME}'))
    return template.replace('{USERNAME}', spawner.user.name)


def configure_hub(c: Any, registry: Path = REGISTRY, *, source: Path = SOURCE,
                  published: Path = PUBLISHED, template: str | None = None) -> None:
    """Hub settings: the shared domain registry, every user's domain in their server's
    environment, the student's copy of the course at every start, the course as the
    landing page. `c` may be a fresh traitlets Config (as JupyterHub and TLJH pass it);
    `template` names the users' Unix accounts when the spawner sets that only at start.

    The kit resolves the domain by itself, but a terminal's plain `python3 my_node.py`
    does not use the kit: with ROS_DOMAIN_ID set for the whole server (from the same
    registry, when the server starts and the Unix user exists) it joins the student's
    graph too, and `robot-lab doctor` still says the domain is theirs from the registry.
    """
    prepare_registry(registry)
    publish_course(source, published)

    def domain(spawner: Any) -> str:
        from robot_lab.domain import DomainRegistry, user_pool

        uid = pwd.getpwnam(unix_name(spawner, template)).pw_uid
        pool = user_pool({key: value for key, value in (spawner.environment or {}).items()
                          if isinstance(value, str)})
        return str(DomainRegistry(registry).user_domain(uid, pool))

    # On a fresh Config this is a LazyConfigValue, whose update() JupyterHub merges into
    # the trait's value; on a dict set earlier it updates that dict.
    c.Spawner.environment.update({
        'ROBOT_LAB_DOMAIN_REGISTRY': str(registry),
        'ROS_DOMAIN_ID': domain,
        'ROBOT_LAB_DOMAIN_FROM_REGISTRY': domain,
    })
    earlier = c.Spawner.pre_spawn_hook

    def before_spawn(spawner: Any) -> None:
        if callable(earlier):
            earlier(spawner)
        try:
            name = unix_name(spawner, template)
            pwd.getpwnam(name)
        except KeyError:
            return  # not created yet (TLJH): tljh_new_user_create releases the course
        install_course(name, published)

    c.Spawner.pre_spawn_hook = before_spawn
    c.Spawner.default_url = f'/lab/tree/{COURSE_HOME}/notebooks/00_welcome.ipynb'


@hookimpl
def tljh_extra_user_pip_packages() -> list[str]:
    # Not editable: a regular install also writes the ament index entries (data_files).
    return [f'{SOURCE}[kit]']


@hookimpl
def tljh_extra_hub_pip_packages() -> list[str]:
    # The hub reads the domain registry (robot_lab.domain: no ROS needed for that).
    return [str(SOURCE)]


@hookimpl
def tljh_custom_jupyterhub_config(c: Any) -> None:
    configure_hub(c, template=TLJH_USERS)


@hookimpl
def tljh_post_install() -> None:
    prepare_registry()
    subprocess.run([str(USER_PYTHON), '-m', 'ipykernel', 'install', '--sys-prefix',
                    '--name', 'robot_lab', '--display-name', 'robot_lab (ROS 2 Jazzy)'],
                   check=True)


@hookimpl
def tljh_new_user_create(username: str) -> None:
    install_course(username)
