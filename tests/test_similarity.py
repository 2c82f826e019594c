"""Similarity accuses only copies (issue 19, item 5): on a class of independently written
solutions (tests/data/class_independent: five students, five designs, one lab) nobody is
paired; a renamed and reordered copy (tests/data/class_ch6/plagiarised) is; the shipped
test class pairs its copies and never its honest student. No grading here: similarity
reads the hand-ins only."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from conftest import REPO

from robot_lab.grading.package.similarity import (
    CAP,
    FLOOR,
    decide_threshold,
    similar_pairs,
    similarity_report,
)
from robot_lab.grading.package.submission import find_submissions

pytestmark = pytest.mark.no_ros  # reads files only: no ROS_DOMAIN_ID slot

DATA = REPO / 'tests' / 'data'
INDEPENDENT = ('ana', 'ben', 'chen', 'dara', 'eli')


def _independent(root: Path) -> Path:
    for name in INDEPENDENT:
        shutil.copytree(DATA / 'class_independent' / name, root / name)
    return root


def _with_copy(root: Path) -> Path:
    """The independent class, the reference solution, a renamed copy of it, olivia."""
    _independent(root)
    ch6 = DATA / 'class_ch6'
    shutil.copytree(ch6 / 'reference', root / 'alice')
    shutil.copytree(ch6 / 'other_names', root / 'olivia')
    shutil.copytree(ch6 / 'reference', root / 'mallory')
    shutil.copytree(ch6 / 'plagiarised' / 'robot_system', root / 'mallory' / 'robot_system',
                    dirs_exist_ok=True)
    return root


def _named(pairs: list[object]) -> set[frozenset[str]]:
    return {frozenset((p.a, p.b)) for p in pairs}  # type: ignore[attr-defined]


def test_independent_solutions_are_never_paired(tmp_path: Path) -> None:
    pairs, threshold = similar_pairs(find_submissions(_independent(tmp_path)))
    assert pairs == [], [(p.a, p.b, p.similarity) for p in pairs]
    assert threshold.pairs == 10


def test_only_the_copy_is_paired_among_honest_students(tmp_path: Path) -> None:
    pairs, threshold = similar_pairs(find_submissions(_with_copy(tmp_path)))
    assert _named(pairs) == {frozenset({'alice', 'mallory'})}
    [pair] = pairs
    assert pair.similarity > threshold.value >= FLOOR
    # The matching lines are the controller's law, in both students' files.
    law_a = [m for m in pair.matches_a if 'min(limit, gain * (msg.data - target))' in m.code]
    law_b = [m for m in pair.matches_b if 'min(vmax, k * (m.data - goal))' in m.code]
    assert law_a and law_b
    assert law_a[0].file == law_b[0].file == 'robot_system/controller_node.py'
    assert law_a[0].first <= 21 <= law_a[0].last  # the line in alice's file


def test_the_shipped_class_pairs_copies_not_the_honest_student(tmp_path: Path) -> None:
    from test_grade_package import CORRECT, FAULTS, make_class

    root = make_class(tmp_path / 'class')
    page = tmp_path / 'similarity.html'
    pairs = similarity_report(find_submissions(root), page)
    named = _named(pairs)
    assert frozenset({'alice', 'mallory'}) in named
    assert not any('olivia' in p for p in named)
    # Every other student started from the reference: each of them is somebody's copy.
    assert {s for p in named for s in p} == {*CORRECT, *FAULTS} - {'olivia'}
    text = page.read_text()
    assert 'median absolute deviation' in text
    rows = {frozenset(m) for m in re.findall(r'<tr data-a="([^"]+)" data-b="([^"]+)">', text)}
    assert rows == named
    assert 'robot_system/controller_node.py:' in text  # where the matching lines are


@pytest.mark.parametrize(('scores', 'expected'), [
    ([0.1, 0.12, 0.08, 0.15, 0.11, 0.9], FLOOR),  # a quiet class: the floor
    ([0.3, 0.34, 0.28, 0.4, 0.32, 0.36, 0.95], None),  # a noisy one: above the floor
    ([0.95, 0.97, 0.99, 1.0], CAP),  # all alike: the cap still names them
])
def test_the_threshold_follows_the_class(scores: list[float], expected: float | None) -> None:
    threshold = decide_threshold(scores)
    if expected is None:
        assert FLOOR < threshold.value < 0.95
    else:
        assert threshold.value == pytest.approx(expected)
    assert 'median' in threshold.explain()
