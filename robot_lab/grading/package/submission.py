"""Which student handed in what: one entry of SUBMISSIONS per student, and their package.

An entry is a folder or an archive (`.zip`, `.tar.gz`, `.tgz`, `.tar`, `.tar.xz`,
`.tar.bz2`); the student id is its name without the suffix. Anything else in SUBMISSIONS
(a `.rar`, a loose `.py`) is an entry too: it gets a row with 0 and feedback naming the
file and what to hand in, so no student vanishes from the gradebook. Layouts an LMS
produces when an instructor downloads every submission are recognised too:

- Moodle ("Download all submissions", unzipped): `Jane Doe_1234567_assignsubmission_file_/`
  (a folder per student holding what they uploaded) -> student `Jane Doe_1234567`;
- Canvas ("Download Submissions", unzipped): `doejane_12345_67890_mypkg.zip` or
  `doejane_LATE_12345_67890_mypkg.zip` (one file per student, named
  `<login>_[LATE_]<user id>_<submission id>_<file name>`) -> student `doejane`.

Archives are unpacked with bounds (size, file count) and never write outside their
folder: no absolute names, no `..`, no links, devices or FIFOs. Inside an entry the
package (the folder with `package.xml`) sits at the top, one level down, or in a colcon
workspace's `src/`; a student's own `build/ install/ log/` are ignored. SUBMISSIONS may
also be one package folder: one student, named after the folder.
"""

from __future__ import annotations

import re
import shutil
import tarfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

from robot_lab.errors import RobotLabError

__all__ = ['ARCHIVE_SUFFIXES', 'Submission', 'copy_submission', 'find_package',
           'find_submissions', 'is_archive', 'student_of', 'unpack']

_MOODLE = re.compile(r'^(?P<student>.+?_\d+)_(assignsubmission|onlinetext)_\w*$')
_CANVAS = re.compile(r'^(?P<student>[^_]+)_(LATE_)?\d+_\d+_.+$')
_SKIP = {'build', 'install', 'log', '__pycache__', '__MACOSX', '.git'}
ARCHIVE_SUFFIXES = ('.zip', '.tar.gz', '.tgz', '.tar', '.tar.xz', '.tar.bz2')
MAX_UNZIPPED = 50 * 1024 * 1024  # bytes a submission's archive may expand to
MAX_FILES = 5000
HAND_IN = ('hand in the package folder (with package.xml) as a .zip or .tar.gz, e.g. '
           '`zip -r mypkg.zip mypkg` or `tar czf mypkg.tar.gz mypkg`, without build/ '
           'install/ log/')


@dataclass(frozen=True)
class Submission:
    """One student's entry: `source` is a folder, an archive, or a file that is neither."""

    student: str
    source: Path


def is_archive(path: Path) -> bool:
    return path.name.lower().endswith(ARCHIVE_SUFFIXES)


def _stem(entry: Path) -> str:
    lower = entry.name.lower()
    for suffix in ARCHIVE_SUFFIXES:
        if lower.endswith(suffix):
            return entry.name[:-len(suffix)]
    return entry.stem if entry.is_file() and entry.suffix else entry.name


def student_of(entry: Path) -> str:
    """The student id an LMS download names an entry after (else the name without suffix)."""
    name = _stem(entry)
    for pattern in (_MOODLE, _CANVAS):
        match = pattern.match(name)
        if match:
            return match['student']
    return name



def find_submissions(root: str | Path) -> list[Submission]:
    """Every student's entry under `root` (or `root` itself when it is one package/archive)."""
    path = Path(root)
    if not path.exists():
        raise RobotLabError('no such folder of submissions', file=path,
                            fix='give the folder holding one folder or archive per student')
    if path.is_file():
        return [Submission(student_of(path), path)]
    if (path / 'package.xml').is_file() or (path / 'src').is_dir():
        return [Submission(path.resolve().name, path)]
    found: dict[str, Submission] = {}
    for entry in sorted(path.iterdir()):
        if entry.name.startswith('.') or entry.name in _SKIP:
            continue
        student = student_of(entry)
        if student in found:  # Canvas: a resubmission; the later file name sorts last
            student = f'{student}-{entry.name}'
        found[student] = Submission(student, entry)
    return list(found.values())


def _too_big(archive: Path, count: int, size: int) -> None:
    if count > MAX_FILES:
        raise RobotLabError(f'{archive.name} holds {count} files (limit {MAX_FILES})',
                            fix='pack only the package, without build/ install/ log/')
    if size > MAX_UNZIPPED:
        raise RobotLabError(f'{archive.name} expands to more than {MAX_UNZIPPED >> 20} MB',
                            fix='pack only the package, without build/ install/ log/')


def _inside(target: Path, name: str) -> Path | None:
    """Where archive member `name` goes, or None when it would leave `target`."""
    if name.startswith(('/', '\\')) or re.match(r'^[A-Za-z]:', name):
        return None
    dest = (target / name).resolve()
    return dest if dest.is_relative_to(target.resolve()) else None


def _extract_zip(archive: Path, target: Path) -> int:
    try:
        with zipfile.ZipFile(archive) as zf:
            infos = zf.infolist()
            _too_big(archive, len(infos), sum(i.file_size for i in infos))
            written = 0
            for info in infos:
                dest = _inside(target, info.filename)
                if dest is None or (info.external_attr >> 16) & 0o170000 == 0o120000:
                    continue  # '../', an absolute name, a symlink: never written
                if info.is_dir():
                    dest.mkdir(parents=True, exist_ok=True)
                    continue
                dest.parent.mkdir(parents=True, exist_ok=True)
                with zf.open(info) as src, dest.open('wb') as out:
                    shutil.copyfileobj(src, out)
                written += 1
            return written
    except zipfile.BadZipFile:
        raise RobotLabError(f'{archive.name} is not a readable zip file', fix=HAND_IN) from None


def _extract_tar(archive: Path, target: Path) -> int:
    try:
        with tarfile.open(archive) as tf:
            members = tf.getmembers()
            _too_big(archive, len(members), sum(m.size for m in members if m.isfile()))
            safe = [m for m in members if (m.isfile() or m.isdir())
                    and _inside(target, m.name) is not None]
            # data_filter: no absolute names, no '..', no links/devices, sane modes.
            tf.extractall(target, members=safe, filter='data')
            return sum(1 for m in safe if m.isfile())
    except (tarfile.TarError, EOFError, OSError) as err:
        raise RobotLabError(f'{archive.name} is not a readable tar archive ({err})',
                            fix=HAND_IN) from None


def _extract(archive: Path, target: Path) -> None:
    """Unpack with bounds; an archive with no file in it is an error naming it."""
    is_zip = archive.name.lower().endswith('.zip')
    written = (_extract_zip if is_zip else _extract_tar)(archive, target)
    if written == 0:
        raise RobotLabError(f'{archive.name} is empty', fix=HAND_IN)


def _ignore(_folder: str, names: list[str]) -> list[str]:
    return [n for n in names if n in _SKIP]


def _not_a_package(path: Path) -> RobotLabError:
    kind = f'a {path.suffix} file' if path.suffix else 'a file'
    return RobotLabError(f'{path.name} is {kind}, not a package folder or a .zip/.tar.gz of '
                         'one', fix=HAND_IN)


def copy_submission(submission: Submission, target: Path) -> Path:
    """The entry's files copied (or unpacked) into `target`, without build/install/log;
    a RobotLabError naming the student's file (never a grader path) when it holds none."""
    target.mkdir(parents=True, exist_ok=True)
    source = submission.source
    if source.is_file():
        if not is_archive(source):
            raise _not_a_package(source)
        _extract(source, target)
    else:
        shutil.copytree(source, target, ignore=_ignore, dirs_exist_ok=True, symlinks=True)
    # A Moodle folder holds the uploaded files: a single archive inside is the package.
    inner = [p for p in target.iterdir() if not p.name.startswith('.')]
    if not inner:
        raise RobotLabError(f'{source.name} is empty', fix=HAND_IN)
    if len(inner) == 1 and inner[0].is_file():
        if not is_archive(inner[0]):
            raise _not_a_package(inner[0])
        _extract(inner[0], target)
        inner[0].unlink()
    return target


def _packages_in(folder: Path) -> list[Path]:
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir()
                  if p.is_dir() and p.name not in _SKIP and (p / 'package.xml').is_file())


def find_package(root: Path, shown: str | None = None) -> Path:
    """The student's package: at `root`, one level down, or in a workspace's `src/`.

    `shown`: the name the error gives the entry (the student's file, never a grader path).
    """
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
        files = sorted(str(p.relative_to(root)) for p in root.rglob('*') if p.is_file())
        held = ', '.join(files[:5]) + (f' and {len(files) - 5} more' if len(files) > 5 else '')
        raise RobotLabError(f'no ROS 2 package (no package.xml) in {shown or root.name}'
                            + (f' (it holds {held})' if files else ''), fix=HAND_IN)
    if len(candidates) > 1:
        # A workspace with several packages: the one with a launch file is the lab's.
        with_launch = [c for c in candidates if (c / 'launch').is_dir()]
        candidates = with_launch or candidates
    return candidates[0]


def unpack(submission: Submission, target: Path) -> Path:
    """The entry copied or unpacked into `target`, and the package folder in it; a
    RobotLabError naming the student's file and what to hand in when there is none."""
    unpacked = copy_submission(submission, target)
    return find_package(unpacked, shown=submission.source.name)
