"""What the grader hands back, from reports (no grading run): feedback pages that carry their
pictures, file names that keep the student id, the run's last line (issue 19)."""

from __future__ import annotations

import base64
from pathlib import Path

import pytest

from robot_lab.grading.report import (
    CheckOutcome,
    StudentReport,
    ascii_name,
    run_summary,
    safe_name,
    write_outputs,
)

pytestmark = pytest.mark.no_ros  # reads files only: no ROS_DOMAIN_ID slot

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
    assert (out / 'feedback' / 'José_Núñez_1234567.graph.png').read_bytes() == PNG  # beside
    assert (out / 'feedback' / 'jose_nunez_1234567.html').is_file()
    assert (out / 'results' / 'José_Núñez_1234567.json').is_file()
    plain = write_outputs(tmp_path / 'plain', [report], ascii_names=True)
    assert (plain / 'feedback' / 'Jose_Nunez_1234567.html').is_file()


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


def test_summary_names_the_crashed_the_stopped_and_the_late(tmp_path: Path) -> None:
    from robot_lab.grading.summary import write_summary

    crashed, stopped = _report('gus', 0.0, 'error'), _report('leo', 1.0, 'timeout')
    crashed.checks[1].score = 0.0  # nothing earned
    late = _report('ann', 2.0)
    late.late_days, late.penalty, late.submitted = 3, 0.9, '2026-11-23 10:00'
    late.elapsed, stopped.elapsed = 12.5, 300.0
    page = write_summary(tmp_path / 'summary.html', [late, crashed, stopped], 'lab',
                         not_handed_in=['Lena (Participant 5)']).read_text()
    short = page[page.index('id="not-graded"'):page.index('id="missing"')]
    assert '<td>gus</td><td>error</td>' in short and '<td>leo</td><td>timeout</td>' in short
    assert '<td>gus</td>' in page[page.index('id="zero"'):page.index('id="not-graded"')]
    assert '<td>ann</td><td>2026-11-23 10:00</td><td>3</td><td>0.9</td>' in page
    slowest = page[page.index('id="slowest"'):]
    assert slowest.index('leo') < slowest.index('ann') < slowest.index('gus')
    assert 'Lena (Participant 5)' in page


def test_moodle_locked_rows_and_dates_in_either_order(tmp_path: Path) -> None:
    from robot_lab.grading.roster import read_roster

    sheet = tmp_path / 'worksheet.csv'
    sheet.write_text('Identifier,Full name,Grade,Maximum Grade,Grade can be changed,'
                     'Last modified (submission),Feedback comments\n'
                     'Participant 7,Ann,,10.00,No,"Monday, November 23, 2026, 1:30 PM",\n'
                     'Participant 8,Bo,,10.00,Yes,"Monday, 23 November 2026, 13:30",\n')
    roster = read_roster(sheet)
    sources = {'Ann_7': 'Ann_7_assignsubmission_file_', 'Bo_8': 'Bo_8_assignsubmission_file_'}
    times = roster.times(sources)
    assert times['Ann_7'].at == times['Bo_8'].at  # US and European spellings alike
    ann, bo = _report('Ann_7', 2.0), _report('Bo_8', 1.0)
    result = roster.fill([ann, bo], sources, tmp_path / 'back.csv')
    assert result.locked == ['Ann_7'] and result.filled == 1
    rows = (tmp_path / 'back.csv').read_text().splitlines()
    assert rows[1].startswith('Participant 7,Ann,,10.00,No')  # left as it was
    assert rows[2].startswith('Participant 8,Bo,6.67,10.00,Yes')  # 2/3 of 10


def test_unclear_inputs_are_one_line_errors(tmp_path: Path) -> None:
    import pytest

    from robot_lab.errors import RobotLabError
    from robot_lab.grading.late import parse_due
    from robot_lab.grading.package.grade import select
    from robot_lab.grading.package.submission import Submission
    from robot_lab.grading.roster import read_roster

    with pytest.raises(RobotLabError, match="write it as 'YYYY-MM-DD HH:MM'"):
        parse_due('next friday')
    export = tmp_path / 'canvas.csv'
    export.write_text('Student,ID,SIS User ID,SIS Login ID,Section,Lab 1 (1),Lab 2 (2)\n'
                      '    Points Possible,,,,,10,10\n')
    with pytest.raises(RobotLabError, match=r'Lab 1 \(1\); Lab 2 \(2\).*--roster-column'):
        read_roster(export)
    assert read_roster(export, 'Lab 2').column == 6
    (tmp_path / 'other.csv').write_text('name,points\nann,3\n')
    with pytest.raises(RobotLabError, match='not a Moodle grading worksheet nor a Canvas'):
        read_roster(tmp_path / 'other.csv')
    with pytest.raises(RobotLabError, match='--only: no hand-in for zed'):
        select([Submission('ann', tmp_path)], ['ann', 'zed'])


def test_the_lms_comment_is_short_and_says_what_to_read() -> None:
    from robot_lab.grading.roster import comment

    missed = _report('wei', 0.0)
    assert comment(missed) == '1/3. Not met: builds. Details in the feedback file.'
    nothing = _report('gus', 0.0)
    nothing.checks[1].score = 0.0
    assert comment(nothing).startswith('0/3. No check met (nothing could be graded')
