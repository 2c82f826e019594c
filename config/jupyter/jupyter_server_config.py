"""JupyterLab as the course's lab bench (`./kit start`, `./kit lab` pass this file).

Its terminals are ROS 2 terminals: an interactive, non-login bash whose rcfile (next to
this file) puts the kit's venv first on PATH — a login shell would read /etc/profile, which
on Debian resets PATH and loses `ros2` — sets the student's ROS domain and workspace, and
starts where the file browser is rooted (the student's course folder). The server listens
on 127.0.0.1 only.
"""

import os
import sys

c = get_config()  # type: ignore[name-defined]  # noqa: F821 (Jupyter's config loader)

_here = os.path.dirname(os.path.abspath(__file__))
# The venv whose jupyter runs this server is the kit's: terminals activate it.
os.environ.setdefault('ROBOT_LAB_VENV', sys.prefix)
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

c.ServerApp.ip = '127.0.0.1'
c.ServerApp.terminado_settings = {
    'shell_command': ['/bin/bash', '--rcfile', os.path.join(_here, 'ros_terminal.bashrc'), '-i'],
}
