"""What the grader hands back, from reports (no grading run): feedback pages that carry their
pictures, file names that keep the student id, the run's last line (issue 19)."""

from __future__ import annotations

import base64
from pathlib import Path

from robot_lab.grading.report import (
    CheckOutcome,
    StudentReport,
    ascii_name,
    run_summary,
    safe_name,
    write_outputs,
)

PNG = base64.b64decode(
    'iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8/5+hHgAHggJ/PchI7wAAAABJRU5ErkJggg==')


def _report(student: str, score: float, status: str = 'graded') -> StudentReport:
    return StudentReport(student, [CheckOutcome('builds', 'Builds', score, 2.0, 'built'),
                                   CheckOutcome('readme', 'README', 1.0, 1.0)],
                         status=status, error='stopped after 300 s' if status != 'graded' else '')


def test_feedback_html_carries_its_picture_and_keeps_the_unicode_id(tmp_path: Path) -> None:
    picture = tmp_path / 'graph.png'
    picture.write_bytes(PNG)
    report = _report('José Núñez_1234567', 2.0)
    report.images = [picture]
    out = write_outputs(tmp_path / 'out', [report, _report('jose nunez/1234567', 0.0)])
    page = (out / 'feedback' / 'José_Núñez_1234567.html').read_text()
    assert f'src="data:image/png;base64,{base64.b64encode(PNG).decode()}"' in page
    markdown = (out / 'feedback' / 'José_Núñez_1234567.md').read_text()
    assert '(José_Núñez_1234567.graph.png)' in markdown  # beside the .md, as a file
    assert (out / 'feedback' / 'jose_nunez_1234567.html').is_file()
    assert (out / 'results' / 'José_Núñez_1234567.json').is_file()


def test_names_never_leave_the_folder_and_never_collide(tmp_path: Path) -> None:
    assert safe_name('../../etc/passwd') == 'etc_passwd'
    assert safe_name('.hidden') == 'hidden'
    assert ascii_name('José Núñez_1234567') == 'Jose_Nunez_1234567'
    assert ascii_name('王小明_42') == '王小明_42'  # nothing readable in ASCII: keep the id
    out = write_outputs(tmp_path, [_report('a b', 1.0), _report('a_b', 2.0)])
    assert sorted(p.name for p in (out / 'feedback').glob('*.md')) == ['a_b-2.md', 'a_b.md']


def test_the_last_line_names_who_was_not_fully_graded() -> None:
    reports = [_report('ann', 2.0), _report('gus', 0.0, 'error'), _report('leo', 1.0, 'timeout')]
    assert run_summary(reports) == ('3 student(s): 1 fully graded, 2 not fully graded: '
                                    'gus (error), leo (timeout)')
    assert run_summary(reports[:1]) == '1 student(s): 1 fully graded'
