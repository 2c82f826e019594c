"""robot_lab for a whole class on one JupyterHub host (a The Littlest JupyterHub plugin).

What a course host needs beyond `pip install`:
- the kit and its kernel in the users' environment (`tljh_extra_user_pip_packages`,
  `tljh_post_install`);
- one ROS domain registry for all users, read by the hub too, which sets each user's
  ROS_DOMAIN_ID for their whole server (terminals included). systemd gives each TLJH
  user server a private /tmp and /var/tmp (SystemdSpawner's isolate_tmp), where the
  default registry (/var/tmp/robot_lab/domains.json) would be private too and every
  student would get the same domain. The registry goes to /srv/robot_lab instead;
- a copy of the course in each student's home (~/robot_lab_course; not ~/robot_lab,
  which would shadow the kit's package in a kernel started in the home folder), made
  once and never overwritten, so a student's edits survive updates of the course.

The functions below work for any JupyterHub too (`configure_hub`, `install_course`):
docs/deploy.md shows a plain `jupyterhub_config.py` that uses them, and
tests/test_deploy.py runs one with local users.
"""

from __future__ import annotations

import os
import pwd
import shutil
import subprocess
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
REGISTRY = Path('/srv/robot_lab/domains.json')
COURSE_FOLDERS = ('notebooks', 'exercises')
COURSE_HOME = 'robot_lab_course'
USER_PYTHON = Path('/opt/tljh/user/bin/python')


def prepare_registry(registry: Path = REGISTRY) -> None:
    """The registry's folder, writable by every user like /tmp (sticky)."""
    registry.parent.mkdir(parents=True, exist_ok=True)
    registry.parent.chmod(0o1777)


def install_course(unix_user: str, source: str | Path = SOURCE) -> Path:
    """Copy the course into the user's home once (their copy, theirs to change)."""
    source = Path(source)
    entry = pwd.getpwnam(unix_user)
    target = Path(entry.pw_dir) / COURSE_HOME
    if target.exists():
        return target
    target.mkdir(parents=True)
    for folder in COURSE_FOLDERS:
        shutil.copytree(source / folder, target / folder)
    for path in [target, *target.rglob('*')]:
        os.chown(path, entry.pw_uid, entry.pw_gid)
    return target


def unix_name(spawner: Any) -> str:
    """The Unix user a spawner runs a hub user as (TLJH: `jupyter-<name>`)."""
    template = str(getattr(spawner, 'username_template', '{USERNAME}'))
    return template.replace('{USERNAME}', spawner.user.name)


def configure_hub(c: Any, registry: Path = REGISTRY) -> None:
    """Hub settings: the shared domain registry, every user's domain in their server's
    environment, and the course as the landing page.

    The kit resolves the domain by itself, but a terminal's plain `python3 my_node.py`
    does not use the kit: with ROS_DOMAIN_ID set for the whole server (from the same
    registry, when the server starts and the Unix user exists) it joins the student's
    graph too, and `robot-lab doctor` still says the domain is theirs from the registry.
    """
    prepare_registry(registry)

    def domain(spawner: Any) -> str:
        from robot_lab.domain import DomainRegistry, user_pool

        uid = pwd.getpwnam(unix_name(spawner)).pw_uid
        pool = user_pool({key: value for key, value in (spawner.environment or {}).items()
                          if isinstance(value, str)})
        return str(DomainRegistry(registry).user_domain(uid, pool))

    environment = dict(c.Spawner.environment or {})
    environment['ROBOT_LAB_DOMAIN_REGISTRY'] = str(registry)
    environment['ROS_DOMAIN_ID'] = domain
    environment['ROBOT_LAB_DOMAIN_FROM_REGISTRY'] = domain
    c.Spawner.environment = environment
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
    configure_hub(c)


@hookimpl
def tljh_post_install() -> None:
    prepare_registry()
    subprocess.run([str(USER_PYTHON), '-m', 'ipykernel', 'install', '--sys-prefix',
                    '--name', 'robot_lab', '--display-name', 'robot_lab (ROS 2 Jazzy)'],
                   check=True)


@hookimpl
def tljh_new_user_create(username: str) -> None:
    install_course(username)
