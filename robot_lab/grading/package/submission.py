"""Which student handed in what: one entry of SUBMISSIONS per student, and their package.

An entry is a folder or a `.zip`; the student id is its name (without `.zip`). Layouts an
LMS produces when an instructor downloads every submission are recognised too:

- Moodle ("Download all submissions", unzipped): `Jane Doe_1234567_assignsubmission_file_/`
  (a folder per student holding what they uploaded) -> student `Jane Doe_1234567`;
- Canvas ("Download Submissions", unzipped): `doejane_12345_67890_mypkg.zip` or
  `doejane_LATE_12345_67890_mypkg.zip` (one file per student, named
  `<login>_[LATE_]<user id>_<submission id>_<file name>`) -> student `doejane`.

Inside an entry the package (the folder with `package.xml`) sits at the top, one level
down, or in a colcon workspace's `src/`; a student's own `build/ install/ log/` are ignored.
SUBMISSIONS may also be one package folder: one student, named after the folder.
"""

from __future__ import annotations

import re
import shutil
import zipfile
from dataclasses import dataclass
from pathlib import Path

from robot_lab.errors import RobotLabError

__all__ = ['Submission', 'copy_submission', 'find_package', 'find_submissions']

_MOODLE = re.compile(r'^(?P<student>.+?_\d+)_(assignsubmission|onlinetext)_\w*$')
_CANVAS = re.compile(r'^(?P<student>[^_]+)_(LATE_)?\d+_\d+_.+$')
_SKIP = {'build', 'install', 'log', '__pycache__', '__MACOSX', '.git'}
MAX_UNZIPPED = 50 * 1024 * 1024  # bytes a submission's zip may expand to
MAX_FILES = 5000


@dataclass(frozen=True)
class Submission:
    """One student's entry: `source` is a folder or a .zip."""

    student: str
    source: Path


def _student_of(entry: Path) -> str:
    name = entry.name[:-4] if entry.suffix.lower() == '.zip' else entry.name
    for pattern in (_MOODLE, _CANVAS):
        match = pattern.match(name)
        if match:
            return match['student']
    return name


def find_submissions(root: str | Path) -> list[Submission]:
    """Every student's entry under `root` (or `root` itself when it is one package/zip)."""
    path = Path(root)
    if not path.exists():
        raise RobotLabError('no such folder of submissions', file=path,
                            fix='give the folder holding one folder or .zip per student')
    if path.is_file():
        if path.suffix.lower() != '.zip':
            raise RobotLabError('a submission is a folder or a .zip', file=path,
                                fix='give the folder of submissions, a package folder or a .zip')
        return [Submission(_student_of(path), path)]
    if (path / 'package.xml').is_file() or (path / 'src').is_dir():
        return [Submission(path.resolve().name, path)]
    found: dict[str, Submission] = {}
    for entry in sorted(path.iterdir()):
        if entry.name.startswith('.') or entry.name in _SKIP:
            continue
        if entry.is_dir() or entry.suffix.lower() == '.zip':
            student = _student_of(entry)
            if student in found:  # Canvas: a resubmission; the later file name sorts last
                student = f'{student}-{entry.name}'
            found[student] = Submission(student, entry)
    return list(found.values())


def _extract(archive: Path, target: Path) -> None:
    """Unzip with bounds: total size, file count, and no path leaving `target`."""
    try:
        with zipfile.ZipFile(archive) as zf:
            infos = zf.infolist()
            if len(infos) > MAX_FILES:
                raise RobotLabError(f'the zip holds {len(infos)} files (limit {MAX_FILES})',
                                    file=archive, fix='zip only the package, without build/')
            if sum(i.file_size for i in infos) > MAX_UNZIPPED:
                raise RobotLabError(f'the zip expands to more than {MAX_UNZIPPED >> 20} MB',
                                    file=archive, fix='zip only the package, without build/')
            root = target.resolve()
            for info in infos:
                dest = (target / info.filename).resolve()
                if not dest.is_relative_to(root):
                    continue  # '../' or an absolute name: never written outside
                if info.is_dir():
                    dest.mkdir(parents=True, exist_ok=True)
                    continue
                dest.parent.mkdir(parents=True, exist_ok=True)
                with zf.open(info) as src, dest.open('wb') as out:
                    shutil.copyfileobj(src, out)
    except zipfile.BadZipFile:
        raise RobotLabError('not a readable zip file', file=archive,
                            fix='ask the student to upload a .zip of the package folder') from None


def _ignore(_folder: str, names: list[str]) -> list[str]:
    return [n for n in names if n in _SKIP]


def copy_submission(submission: Submission, target: Path) -> Path:
    """The entry's files copied (or unzipped) into `target`, without build/install/log."""
    target.mkdir(parents=True, exist_ok=True)
    source = submission.source
    if source.is_file():
        _extract(source, target)
    else:
        shutil.copytree(source, target, ignore=_ignore, dirs_exist_ok=True, symlinks=True)
    # A Moodle folder holds the uploaded files: a single zip inside is the package.
    inner = [p for p in target.iterdir() if not p.name.startswith('.')]
    if len(inner) == 1 and inner[0].suffix.lower() == '.zip':
        _extract(inner[0], target)
        inner[0].unlink()
    return target


def _packages_in(folder: Path) -> list[Path]:
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir()
                  if p.is_dir() and p.name not in _SKIP and (p / 'package.xml').is_file())


def find_package(root: Path) -> Path:
    """The student's package: at `root`, one level down, or in a workspace's `src/`."""
    if (root / 'package.xml').is_file():
        return root
    candidates = _packages_in(root) or _packages_in(root / 'src')
    if not candidates:
        for child in sorted(p for p in root.iterdir() if p.is_dir() and p.name not in _SKIP):
            candidates = _packages_in(child) or _packages_in(child / 'src')
            if (child / 'package.xml').is_file():
                candidates = [child]
            if candidates:
                break
    if not candidates:
        raise RobotLabError('no ROS 2 package found (no package.xml)', file=root,
                            fix='hand in the package folder (with package.xml), a zip of '
                            'it, or a workspace with the package in src/')
    if len(candidates) > 1:
        # A workspace with several packages: the one with a launch file is the lab's.
        with_launch = [c for c in candidates if (c / 'launch').is_dir()]
        candidates = with_launch or candidates
    return candidates[0]
