"""JupyterLab as the course's lab bench (`./kit start`, `./kit lab` pass this file).

Its terminals are ROS 2 terminals: an interactive, non-login bash whose rcfile (next to
this file) puts the kit's venv first on PATH — a login shell would read /etc/profile, which
on Debian resets PATH and loses `ros2` — sets the student's ROS domain and workspace, and
starts where the file browser is rooted (the student's course folder). The server listens
on 127.0.0.1 only.

The Lab is the student's: nbgrader's instructor and exchange tools (the Nbgrader menu,
Create Assignment, Formgrader, Assignment and Course List) are hidden, and their server
extensions off, because a student's Lab has no course database or exchange to show and
they only fail there. nbgrader's Validate button stays (it checks the student's own
notebook). An instructor turns the tools on with ROBOT_LAB_INSTRUCTOR=1 (what
`./kit lab --instructor` sets). JupyterLab's news feed and update check are off: the Lab
contacts no address off this machine.
"""

import os
import sys

c = get_config()  # type: ignore[name-defined]  # noqa: F821 (Jupyter's config loader)

_here = os.path.dirname(os.path.abspath(__file__))
# The venv whose jupyter runs this server is the kit's: terminals activate it.
os.environ.setdefault('ROBOT_LAB_VENV', sys.prefix)
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
# Its terminals' `colcon build` compiles through the kit's warmed compiler cache, as its
# kernels' does (robot_lab/compiler_cache.py; nothing is set without ccache).
try:
    from robot_lab.compiler_cache import apply_compiler_cache
except ImportError:  # a server outside the kit's venv
    pass
else:
    apply_compiler_cache(os.environ)
# nbgrader's Validate handler reads the Jupyter config path at each request: this folder's
# nbgrader_config.py makes a cell that times out fail Validate (it said "Success!").
os.environ['JUPYTER_CONFIG_PATH'] = os.pathsep.join(
    [_here, *(p for p in os.environ.get('JUPYTER_CONFIG_PATH', '').split(os.pathsep)
              if p and p != _here)])

c.ServerApp.ip = '127.0.0.1'
c.ServerApp.terminado_settings = {
    'shell_command': ['/bin/bash', '--rcfile', os.path.join(_here, 'ros_terminal.bashrc'), '-i'],
}
c.LabApp.news_url = None
c.LabApp.check_for_updates_class = 'jupyterlab.NeverCheckForUpdate'
# JupyterLab would still ask "get notified about official Jupyter news?": its setting's
# default becomes Never (lab/labconfig/default_setting_overrides.json; a student may change it).
os.environ['JUPYTER_CONFIG_PATH'] = os.pathsep.join(
    p for p in (os.path.join(_here, 'lab'), os.environ.get('JUPYTER_CONFIG_PATH')) if p)

# nbgrader's JupyterLab plugins an instructor uses (tests/test_lab_bench.py names them too).
INSTRUCTOR_PLUGINS = [
    '@jupyter/nbgrader:menu',
    '@jupyter/nbgrader:create-assignment',
    '@jupyter/nbgrader:formgrader',
    '@jupyter/nbgrader:assignment-list',
    '@jupyter/nbgrader:course-list',
]
# course_list stays on: it also answers /nbgrader_version, which Validate asks first.
INSTRUCTOR_SERVER_EXTENSIONS = [
    'nbgrader.server_extensions.formgrader',
    'nbgrader.server_extensions.assignment_list',
]


def _instructor() -> bool:
    return os.environ.get('ROBOT_LAB_INSTRUCTOR', '').lower() not in ('', '0', 'false', 'no')


def _hide_instructor_plugins(handler: object, page_config: dict) -> dict:  # type: ignore[type-arg]
    """JupyterLab's page-config hook: the student's page loads without those plugins."""
    disabled = set(page_config.get('disabledExtensions', []))
    page_config['disabledExtensions'] = sorted(disabled | set(INSTRUCTOR_PLUGINS))
    return page_config


if not _instructor():
    c.ServerApp.jpserver_extensions = dict.fromkeys(INSTRUCTOR_SERVER_EXTENSIONS, False)
    c.ServerApp.tornado_settings = {'page_config_hook': _hide_instructor_plugins}
