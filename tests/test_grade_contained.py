"""Grading a class an instructor can leave running (issue 19): every entry gets a row,
archives are unpacked safely, checks are behavioural and fair, feedback follows the cause,
and a hostile student's job is contained. The class is graded for real (colcon, the
student's launch file, a live graph); the archive rules are checked without ROS."""

from __future__ import annotations

import io
import tarfile
import zipfile
from pathlib import Path

import pytest
from conftest import REPO, run_cli

from robot_lab.errors import RobotLabError
from robot_lab.grading.package.submission import find_submissions, unpack

DATA = REPO / 'tests' / 'data' / 'class_ch6'
PKG = 'robot_system'


def _tar(path: Path, members: dict[str, bytes], links: dict[str, str] | None = None,
         mode: str = 'w:gz') -> Path:
    with tarfile.open(path, mode) as tf:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tf.addfile(info, io.BytesIO(data))
        for name, target in (links or {}).items():
            info = tarfile.TarInfo(name)
            info.type = tarfile.SYMTYPE
            info.linkname = target
            tf.addfile(info)
    return path


def _package_tar(path: Path, mode: str) -> Path:
    with tarfile.open(path, mode) as tf:
        tf.add(DATA / 'reference', arcname=PKG)
    return path


@pytest.mark.parametrize('suffix,mode', [('.tar.gz', 'w:gz'), ('.tgz', 'w:gz'),
                                         ('.tar', 'w'), ('.tar.xz', 'w:xz'),
                                         ('.tar.bz2', 'w:bz2')])
def test_tar_archives_are_entries_like_zips(tmp_path: Path, suffix: str, mode: str) -> None:
    _package_tar(tmp_path / f'gus{suffix}', mode)
    [sub] = find_submissions(tmp_path)
    assert sub.student == 'gus'
    package = unpack(sub, tmp_path / 'out')
    assert (package / 'package.xml').is_file() and package.name == PKG


def test_unsafe_archive_members_never_leave_the_folder(tmp_path: Path) -> None:
    outside = tmp_path / 'outside'
    outside.mkdir()
    (tmp_path / 'class').mkdir()
    _tar(tmp_path / 'class' / 'eve.tar.gz', {
        f'{PKG}/package.xml': b'<package><name>robot_system</name></package>',
        '../outside/escaped.txt': b'x', '/tmp/absolute.txt': b'x',
    }, links={f'{PKG}/link': str(outside), f'{PKG}/up': '../../outside'})
    package = unpack(find_submissions(tmp_path / 'class')[0], tmp_path / 'job')
    assert package == tmp_path / 'job' / PKG
    assert not (outside / 'escaped.txt').exists() and not Path('/tmp/absolute.txt').exists()
    assert not any(p.is_symlink() for p in (tmp_path / 'job').rglob('*'))
    with zipfile.ZipFile(tmp_path / 'class' / 'zed.zip', 'w') as zf:
        zf.writestr(f'{PKG}/package.xml', '<package/>')
        zf.writestr('../outside/zipped.txt', 'x')
    unpack(find_submissions(tmp_path / 'class')[1], tmp_path / 'job2')
    assert not (outside / 'zipped.txt').exists()


def test_a_bomb_stops_at_the_size_cap(tmp_path: Path) -> None:
    with zipfile.ZipFile(tmp_path / 'bomb.zip', 'w', zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(f'{PKG}/big.bin', b'\0' * (60 << 20))
    with pytest.raises(RobotLabError, match=r'bomb\.zip expands to more than 50 MB'):
        unpack(find_submissions(tmp_path / 'bomb.zip')[0], tmp_path / 'job')


def _odd_entries(root: Path) -> dict[str, str]:
    """Entries that hold no package, and the words their feedback must say."""
    root.mkdir(parents=True, exist_ok=True)
    (root / 'rita.rar').write_bytes(b'Rar!\x1a\x07\x00' + b'\0' * 64)
    (root / 'pete.py').write_text('import rclpy\n')
    with zipfile.ZipFile(root / 'emma.zip', 'w'):
        pass
    folder = root / 'Otto Ode_7654321_assignsubmission_file_'
    folder.mkdir()
    (folder / 'otto.rar').write_bytes(b'Rar!')
    return {'rita': 'rita.rar is a .rar file', 'pete': 'pete.py is a .py file',
            'emma': 'emma.zip is empty', 'Otto Ode_7654321': 'otto.rar is a .rar file'}


def test_entries_without_a_package_say_which_file_and_what_to_hand_in(tmp_path: Path) -> None:
    expected = _odd_entries(tmp_path / 'class')
    subs = {s.student: s for s in find_submissions(tmp_path / 'class')}
    assert set(subs) == set(expected)
    for student, words in expected.items():
        with pytest.raises(RobotLabError) as caught:
            unpack(subs[student], tmp_path / 'job' / student)
        assert words in caught.value.message, caught.value.message
        assert '.zip or .tar.gz' in (caught.value.fix or '')
        assert str(tmp_path) not in str(caught.value)  # no grader path
    listed = run_cli('grade', str(tmp_path / 'class'), '--lab', 'ch6-lab1', '--list')
    assert listed.returncode == 0, listed.stderr
    for student, words in expected.items():
        line = next(x for x in listed.stdout.splitlines() if x.startswith(student))
        assert 'NOT GRADABLE' in line and words in line, listed.stdout
