"""A notebook's first cell: the same set-up for every lesson, in JupyterLab and under nbval.

It puts the kit's venv on PATH (so `!ros2 …` cells run the kit's verbs), picks the
lesson's ROS_DOMAIN_ID when a test run asks for one (notebooks run by nbval must not hear
each other or the tests), and names the scratch workspace where student work goes —
never the repository. A test run (a domain base in the environment) is headless, and its
workspace is a temporary folder shared by the notebooks of that run.

Under nbgrader's autograder (NBGRADER_EXECUTION=autograde) each notebook is one student's
submission: it gets a workspace of its own (new, removed when the kernel ends — never the
instructor's ~/robot_lab_ws, where the previous student's files would be) and a domain
leased from the host's registry for the kernel's life (never a user's, never another
job's). nbgrader's Validate keeps the student's own workspace and domain: their notebooks
build on each other's packages.
"""

from __future__ import annotations

import atexit
import os
import re
import shutil
import sys
import tempfile
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robot_lab.widgets.output import is_headless

__all__ = ['Lesson', 'setup']


@dataclass(frozen=True)
class Lesson:
    """What `setup()` decided; printed at the top of each notebook."""

    notebook: str
    domain_id: int
    workspace: Path

    def __str__(self) -> str:
        return (f'{self.notebook}: ROS_DOMAIN_ID={self.domain_id}, '
                f'workspace {self.workspace}')


# Under nbval, lessons 9-13 would land on nbgrader's 70 and test modules' 71-74:
# tests/conftest.py lays them out at 51-54 and 60.
_LATE_NBVAL = {9: 51, 10: 52, 11: 53, 12: 54, 13: 60}


def _number(notebook: str) -> int:
    found = re.match(r'(\d+)', notebook)
    return int(found.group(1)) if found else 0


# Lessons 01-06 build one package (my_robot_system), each on the one before; 00 and 07-12
# start from nothing of the student's (07 and 08 create packages of their own, 09 its
# interfaces, 10 runs turtlesim's tutorials, 11 and 12 make tf2 and description packages).
_CONTINUED = range(2, 7)


def first_of_chain(notebook: str) -> int:
    """The lesson whose work `notebook` continues (itself when it stands alone): a test run
    runs a chain in order, in one workspace, and the chains beside each other."""
    number = _number(notebook)
    return 1 if number in _CONTINUED else number


def _autograding() -> bool:
    return os.environ.get('NBGRADER_EXECUTION', '').strip() == 'autograde'


def _domain(notebook: str) -> int:
    """ROBOT_LAB_NOTEBOOK_DOMAIN_BASE + lesson number when set (test runs); else as is.

    Without it, a test run's ROBOT_LAB_TEST_DOMAIN_BASE still keeps notebooks apart from
    the test modules (which count up from base + 1): lessons use base + 60 + number.
    """
    if _autograding():
        from robot_lab.domain import process_domain

        return process_domain(f'nbgrader autograde {notebook}')
    number = _number(notebook)
    base = os.environ.get('ROBOT_LAB_NOTEBOOK_DOMAIN_BASE', '').strip()
    if base:
        return (int(base) + number) % 102
    test_base = os.environ.get('ROBOT_LAB_TEST_DOMAIN_BASE', '').strip()
    if test_base:  # nbval: base + 61-69 for lessons 0-8, 51-54 and 60 for 9-13 (conftest.py)
        return (int(test_base) + _LATE_NBVAL.get(number, 61 + number) - 1) % 100 + 1
    from robot_lab.env import apply_ros_defaults

    # ROS_DOMAIN_ID, or the user's own (robot_lab/domain.py): notebook 05 sees 03's nodes.
    return int(apply_ros_defaults()['ROS_DOMAIN_ID'])


_fresh: list[Path] = []


def run_workspace(parent: int) -> Path:
    """The workspace of the kernels process `parent` starts in a test run (nbval, or a
    pytest-xdist worker of `./kit test`): one folder, so notebook 02 finds the package
    notebook 01 created; the run removes it when it ends (tests/conftest.py)."""
    return Path(tempfile.gettempdir()) / f'robot_lab_ws-{os.getuid()}-{parent}'


def _workspace() -> Path:
    if _autograding():
        if not _fresh:  # one per kernel, however often the set-up cell runs
            _fresh.append(Path(tempfile.mkdtemp(prefix='robot_lab_autograde_')))
            atexit.register(shutil.rmtree, _fresh[0], True)
        os.environ['ROBOT_LAB_WORKSPACE'] = str(_fresh[0])
    elif 'ROBOT_LAB_WORKSPACE' not in os.environ and is_headless():
        os.environ['ROBOT_LAB_WORKSPACE'] = str(run_workspace(os.getppid()))
    from robot_lab.pkg.workspace import workspace_dir

    return workspace_dir()


def _warm_graph() -> None:
    """A graph daemon for this lesson's domain that ends with this kernel, so the
    notebook's `!ros2 …` commands answer from a warm graph (in 05, 0.1-0.2 s a command
    where each was a cold 0.5-1 s: before, a daemon a `!` command started ended with it).
    A lesson on the student's own domain usually finds the one `./kit start` runs. A
    graded kernel (nbgrader autograde) runs briefly in a job whose processes the grader
    accounts for: it gets none."""
    if _autograding():
        return
    from robot_lab.graph.daemon import OWNER_VARIABLE, start_for_later

    os.environ[OWNER_VARIABLE] = str(os.getpid())
    start_for_later(owner=os.getpid())


def _in_test_run() -> bool:
    """A test run (nbval under `./kit test`, CI) names a domain base for its notebooks."""
    return any(os.environ.get(name, '').strip() for name in
               ('ROBOT_LAB_NOTEBOOK_DOMAIN_BASE', 'ROBOT_LAB_TEST_DOMAIN_BASE'))


def _short_errors(workspace: Path) -> None:
    """Under nbgrader (Validate, autograde), a failed check or a kit error shows as its
    message alone, wrapped, with the paths the student knows: what nbgrader's feedback page
    and Validate print holds no traceback into the kit's code or the grader's folders.
    Every other error keeps its traceback, cut to the student's own frames."""
    try:
        from IPython import get_ipython
    except ImportError:
        return
    shell = get_ipython()
    if shell is None:
        return
    from robot_lab.errors import RobotLabError
    from robot_lab.notebook_cell import show_their_error

    def short(shell: Any, etype: type[BaseException], value: BaseException, tb: Any,
              tb_offset: int | None = None) -> list[str]:
        if not (issubclass(etype, RobotLabError) or etype.__name__ == 'CheckError'):
            return show_their_error(shell, etype, value, tb)
        text = f'{etype.__name__}: {value}'.replace(str(workspace), '~/robot_lab_ws')
        home = str(Path.home())
        text = text.replace(home + '/', '~/') if home != '/' else text
        lines = textwrap.wrap(text, 88, break_long_words=False, break_on_hyphens=False)
        shell._showtraceback(etype, value, lines)
        return lines

    shell.set_custom_exc((Exception,), short)


def setup(notebook: str) -> Lesson:
    """Prepare this kernel for lesson `notebook` (e.g. '04_parameters'); what was chosen."""
    if _in_test_run() or _autograding():
        # Nobody watches a test run: widgets leave static images, work goes to a temp folder.
        os.environ.setdefault('ROBOT_LAB_HEADLESS', '1')
    bin_dir = os.path.dirname(sys.executable)
    path = os.environ.get('PATH', '').split(os.pathsep)
    if bin_dir not in path:
        os.environ['PATH'] = os.pathsep.join([bin_dir, *path])
    domain = _domain(notebook)
    os.environ['ROS_DOMAIN_ID'] = str(domain)
    from robot_lab.env import apply_ros_defaults

    apply_ros_defaults()
    from robot_lab.shared_memory import sweep_dead_segments

    sweep_dead_segments()  # a restarted kernel's killed nodes left their memory behind
    lesson = Lesson(notebook, domain, _workspace())
    _warm_graph()
    from robot_lab.notebook_cell import show_their_errors

    show_their_errors()  # a cell's error: the student's frames and a Try: line
    from robot_lab.script_cells import decode_whole_characters

    decode_whole_characters()  # IPython 8 (Python 3.10): a `°` in %%bash output stays whole
    if os.environ.get('NBGRADER_EXECUTION', '').strip():
        _short_errors(lesson.workspace)
    return lesson
