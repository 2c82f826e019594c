"""Similarity calibrated on small classes (issue 51, item 5): in classes of 10-30 honest
students whose scores cluster near the floor nobody is named, and renamed or reordered
copies still are. The honest students are tests/data/class_independent (28 packages, each
its own design and style, some written from the ROS 2 tutorial or the lab handout) and the
two honest students of tests/data/class_ch6; the copies are
tests/data/class_independent/.copies (six students' packages renamed, reordered and
reformatted by another) and class_ch6's Mallory. Reads files only: no ROS."""

from __future__ import annotations

import functools
import random
import shutil
import tempfile
from pathlib import Path

import pytest
from conftest import REPO

from robot_lab.grading.package.similarity import FLOOR, Shape, compare, shape
from robot_lab.grading.package.similarity import _student_files as student_files
from robot_lab.grading.package.submission import Submission

pytestmark = pytest.mark.no_ros

DATA = REPO / 'tests' / 'data'
INDEPENDENT = DATA / 'class_independent'
COPIES = {'abe': 'ana', 'cody': 'chen', 'fin': 'fay', 'gil': 'gus', 'hal': 'hana',
          'quade': 'quinn', 'mallory': 'alice'}


@functools.cache
def _shapes() -> dict[str, Shape]:
    """Every student's code, honest and copied, read once (on first use, not collection)."""
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        folders = {p.name: p for p in INDEPENDENT.iterdir() if not p.name.startswith('.')}
        folders |= {p.name: p for p in (INDEPENDENT / '.copies').iterdir() if p.is_dir()}
        folders['alice'] = DATA / 'class_ch6' / 'reference'
        folders['olivia'] = DATA / 'class_ch6' / 'other_names'
        shutil.copytree(folders['alice'], root / 'mallory')
        shutil.copytree(DATA / 'class_ch6' / 'plagiarised' / 'robot_system',
                        root / 'mallory' / 'robot_system', dirs_exist_ok=True)
        folders['mallory'] = root / 'mallory'
        return {name: shape(student_files(Submission(name, path), root / 'work'))
                for name, path in folders.items()}


def _honest() -> list[str]:
    return sorted(set(_shapes()) - set(COPIES))


def _classes(seed: int) -> list[list[str]]:
    """Honest classes of 10 to all 30 students: fixed draws, the same on every run."""
    draw = random.Random(seed)
    sizes = [10, 10, 12, 15, 15, 18, 20, 24, 27, len(_honest())]
    return [sorted(draw.sample(_honest(), size)) for size in sizes]


def _named(names: list[str]) -> tuple[set[frozenset[str]], float]:
    pairs, threshold = compare(names, [_shapes()[n] for n in names])
    return {frozenset((p.a, p.b)) for p in pairs}, threshold.value


def test_the_honest_students_are_many_and_alike_only_by_the_lab() -> None:
    assert len(_honest()) == 30
    pairs, threshold = compare(_honest(), [_shapes()[n] for n in _honest()])
    scores = sorted((p.similarity for p in pairs), reverse=True)
    assert scores == []  # the whole class: nobody named
    assert threshold.value >= FLOOR


@pytest.mark.parametrize('seed', [1, 2, 3])
def test_honest_classes_of_10_to_30_name_nobody(seed: int) -> None:
    for names in _classes(seed):
        named, line = _named(names)
        assert named == set(), (len(names), line, named)


@pytest.mark.parametrize('seed', [4, 5])
def test_copies_are_named_beside_honest_classes(seed: int) -> None:
    """Each class: an honest draw, every copied student's original, and the copies (up to
    30 students in all); exactly the copied pairs are named."""
    draw = random.Random(seed)
    originals = set(COPIES.values())
    for size in (3, 6, 10, 16):
        others = draw.sample(sorted(set(_honest()) - originals), size)
        names = sorted({*others, *originals, *COPIES})
        assert 10 <= len(names) <= 30
        named, line = _named(names)
        assert named == {frozenset(p) for p in COPIES.items()}, (len(names), line, named)


def test_the_line_falls_between_honest_pairs_and_copies() -> None:
    """The margins the floor was chosen from (the FLOOR comment of similarity.py): in one
    class of all 37 students, the copied pairs are named and nobody else; every honest
    pair scores at least 0.1 under the floor, every copy at least 0.1 over it."""
    everyone = sorted(_shapes())
    named, _ = _named(everyone)
    copied = {frozenset(p) for p in COPIES.items()}
    assert named == copied
    pairs, _ = compare(everyone, [_shapes()[n] for n in everyone], every_pair=True)
    honest = max(p.similarity for p in pairs if frozenset((p.a, p.b)) not in copied)
    copy = min(p.similarity for p in pairs if frozenset((p.a, p.b)) in copied)
    assert honest <= FLOOR - 0.1 < FLOOR + 0.1 <= copy, (honest, copy)


def test_type_annotations_change_nothing() -> None:
    """Annotating a copy does not hide it, nor do two annotating students look alike."""
    typed = ('def f(x: int, *rest: str, y: list[str] | None = None) -> None:\n'
             '    z: float = 1.0\n    state: dict[str, int]\n    return {z: x}\n')
    plain = 'def f(x, *rest, y=None):\n    z = 1.0\n    state\n    return {z: x}\n'
    assert shape({'m.py': typed}).fine == shape({'m.py': plain}).fine
