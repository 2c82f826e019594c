"""A Gradescope autograder that grades a package with the kit's own checks.

`robot-lab grade --gradescope-autograder autograder.zip --lab LAB [--rubric FILE]` writes
the zip Gradescope asks for ("Configure Autograder" → upload): `setup.sh` (run once, as
root, in Gradescope's Ubuntu image: installs Python and the kit with its ROS 2 wheels from
PyPI into /autograder/venv), `run_autograder` (run per submission: grades
/autograder/submission and writes /autograder/results/results.json in Gradescope's schema),
the rubric, and the kit's source. Gradescope runs one container per submission on its own
machines, so the class is graded in parallel there.

`python -m robot_lab.grading.package.gradescope --root DIR --rubric FILE` is what
run_autograder calls; `DIR` stands for /autograder (`AUTOGRADER_ROOT` in run_autograder),
so the same script is tried locally on a simulated layout.
"""

from __future__ import annotations

import argparse
import json
import os
import stat
import sys
import zipfile
from pathlib import Path

from robot_lab.errors import RobotLabError
from robot_lab.grading.package.rubric import Limits, Rubric

__all__ = ['autograder_containment', 'grade_in_autograder', 'write_autograder']

# The kit's files `pip install ./kit` needs (its setup.py's packages and data files).
_KIT_FILES = ('setup.py', 'setup.cfg', 'pyproject.toml', 'package.xml', 'README.md')
_KIT_DIRS = ('robot_lab', 'resource', 'launch', 'config')
_SKIP = {'__pycache__', '.pytest_cache', '.mypy_cache'}

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once, as root, to build the autograder's image (Ubuntu 22.04/24.04).
# It installs Python, then the kit and ROS 2 Jazzy (rclpy, Fast DDS, colcon) from PyPI.
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends python3 python3-venv python3-pip ca-certificates
python3 -m venv /autograder/venv
/autograder/venv/bin/python -m pip install --upgrade pip
/autograder/venv/bin/python -m pip install '/autograder/source/kit[kit]'
/autograder/venv/bin/robot-lab --version
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope runs this for each submission: grade /autograder/submission with the rubric
# in this zip and write /autograder/results/results.json. AUTOGRADER_ROOT stands for
# /autograder when it is tried elsewhere; ROBOT_LAB_AUTOGRADER_PYTHON for the venv's python.
set -uo pipefail
ROOT="${{AUTOGRADER_ROOT:-/autograder}}"
PYTHON="${{ROBOT_LAB_AUTOGRADER_PYTHON:-$ROOT/venv/bin/python}}"
export ROS_AUTOMATIC_DISCOVERY_RANGE="${{ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}}"
exec "$PYTHON" -m robot_lab.grading.package.gradescope --root "$ROOT" \\
     --rubric "$ROOT/source/{rubric}"
"""


def _kit_root() -> Path:
    """The kit's source checkout (where its setup.py is), to ship in the zip."""
    root = Path(__file__).resolve().parents[3]
    if not (root / 'setup.py').is_file() or not (root / 'robot_lab').is_dir():
        raise RobotLabError('the kit is not installed from its source folder',
                            fix='run this from a clone of the kit (./kit setup there)')
    return root


def _add(zf: zipfile.ZipFile, name: str, text: str, executable: bool = False) -> None:
    info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
    info.external_attr = ((0o755 if executable else 0o644) | stat.S_IFREG) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    zf.writestr(info, text)


def write_autograder(target: str | Path, rubric: Rubric) -> Path:
    """Write the Gradescope autograder zip for `rubric`; return its path."""
    assert rubric.source is not None
    out = Path(target)
    root = _kit_root()
    rubric_name = f'rubric-{rubric.lab}.yaml'
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, 'w') as zf:
        _add(zf, 'setup.sh', SETUP_SH, executable=True)
        _add(zf, 'run_autograder', RUN_AUTOGRADER.format(rubric=rubric_name), executable=True)
        _add(zf, rubric_name, rubric.source.read_text())
        for name in _KIT_FILES:
            if (root / name).is_file():
                zf.write(root / name, f'kit/{name}')
        for folder in _KIT_DIRS:
            for path in sorted((root / folder).rglob('*')):
                rel = path.relative_to(root)
                if path.is_file() and not _SKIP & set(rel.parts) and path.suffix != '.pyc':
                    zf.write(path, f'kit/{rel.as_posix()}')
    return out


def autograder_containment(limits: Limits) -> str:
    """The containment line of a job in Gradescope's container, printed before it runs.

    With namespaces, the job is fenced in as on an instructor's machine. Without them
    (Docker's seccomp profile refuses `unshare`), refusing would leave the student with no
    grade: the container, one per submission and thrown away after it, is the sandbox
    then, and the line says so and why, never silently."""
    from robot_lab.grading.package.containment import (
        NO_SANDBOX_VAR,
        container_line,
        namespace_problem,
        namespaces_available,
    )
    from robot_lab.grading.package.sandbox import check_can_contain

    if namespaces_available():
        return check_can_contain(limits=limits)
    os.environ[NO_SANDBOX_VAR] = '1'  # for the job run_job starts: no unshare to try
    return container_line(limits, namespace_problem() or 'namespaces were refused')


def grade_in_autograder(root: Path, rubric_file: Path) -> dict[str, object]:
    """Grade `root/submission`; write `root/results/results.json`; return what was written."""
    from robot_lab.grading.package.grade import grade_package
    from robot_lab.grading.package.rubric import load_rubric
    from robot_lab.grading.package.submission import Submission

    results = root / 'results' / 'results.json'
    results.parent.mkdir(parents=True, exist_ok=True)
    try:
        rubric = load_rubric(rubric_file)
        # Gradescope shows run_autograder's output to the instructor, not the student.
        print(autograder_containment(rubric.limits), flush=True)
        report = grade_package(Submission('submission', root / 'submission'), rubric)
        data = report.results_json()
        data['visibility'] = 'visible'
        data['stdout_visibility'] = 'hidden'
        for test in data['tests']:
            test['status'] = 'passed' if test['score'] >= test['max_score'] else 'failed'
    except Exception as err:  # a grader fault: say so, never a silent 0
        data = {'score': 0, 'output': f'The autograder itself failed: {err}. Please tell '
                'your instructor; your submission was not graded.', 'tests': []}
    results.write_text(json.dumps(data, indent=2) + '\n')
    return data


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='python -m robot_lab.grading.package.gradescope')
    parser.add_argument('--root', default='/autograder', type=Path)
    parser.add_argument('--rubric', required=True, type=Path)
    args = parser.parse_args(argv)
    data = grade_in_autograder(args.root, args.rubric)
    print(f'score {data.get("score")}; wrote {args.root}/results/results.json')
    return 0


if __name__ == '__main__':
    sys.exit(main())
