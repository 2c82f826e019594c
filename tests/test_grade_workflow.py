"""The instructor's loop (issue 19, item 6), on a real Moodle class graded for real: the
worksheet written back with grades and comments, late hand-ins from the worksheet's own
submission time, summary.html, then one student regraded with --only after a resubmission
and a rubric change (their row replaced, whose score changed printed, nobody else touched);
the Canvas export filled from the same class's record.

One class run and one --only run serve every assertion (module-scoped fixtures)."""

from __future__ import annotations

import base64
import csv
import io
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from conftest import REPO, run_cli

from robot_lab.grading.gradebook import load_record
from robot_lab.grading.late import LatePolicy, Submitted, parse_due
from robot_lab.grading.roster import read_roster

DATA = REPO / 'tests' / 'data' / 'class_ch6'
PKG = 'robot_system'
pytestmark = pytest.mark.timeout(1800)

ANA, JOSE, WEI, GUS = ('Ana Lima_1001', 'José Núñez_1002', 'Wei Chen_1003', 'Gus Empty_1004')
WORKSHEET = [
    ['Identifier', 'Full name', 'Email address', 'Status', 'Grade', 'Maximum grade',
     'Grade can be changed', 'Last modified (submission)', 'Last modified (grade)',
     'Feedback comments'],
    ['Participant 1001', 'Ana Lima', 'ana@example.edu', 'Submitted for grading', '',
     '100.00', 'Yes', 'Wednesday, 18 November 2026, 3:15 PM', '-', ''],
    ['Participant 1002', 'José Núñez', 'jose@example.edu', 'Submitted for grading', '',
     '100.00', 'Yes', 'Sunday, 22 November 2026, 9:05 AM', '-', ''],
    ['Participant 1003', 'Wei Chen', 'wei@example.edu', 'Submitted for grading', '',
     '100.00', 'Yes', 'Friday, 20 November 2026, 11:58 PM', '-', ''],
    ['Participant 1004', 'Gus Empty', 'gus@example.edu', 'Submitted for grading', '',
     '100.00', 'Yes', 'Friday, 20 November 2026, 10:00 PM', '-', ''],
    ['Participant 1005', 'Lena Absent', 'lena@example.edu', 'No submission', '', '100.00',
     'Yes', '-', '-', ''],
]
DUE = '2026-11-20 23:59'


def _folder(root: Path, student: str) -> Path:
    return root / f'{student}_assignsubmission_file_'


def _wrong_topic(pkg: Path) -> None:
    node = pkg / PKG / 'controller_node.py'
    node.write_text(node.read_text().replace("(Float32, 'distance',", "(Float32, 'distance_m',"))


def _csv(path: Path) -> list[list[str]]:
    return list(csv.reader(io.StringIO(path.read_text(encoding='utf-8-sig'))))


def _rows(out: Path) -> dict[str, dict[str, str]]:
    with (out / 'grades.csv').open() as f:
        return {row['student']: row for row in csv.DictReader(f)}


@pytest.fixture(scope='module')
def moodle_class(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    root = tmp_path_factory.mktemp('moodle') / 'submissions'
    for student in (ANA, JOSE):
        shutil.copytree(DATA / 'reference', _folder(root, student) / PKG)
    shutil.copytree(DATA / 'reference', _folder(root, WEI) / PKG)
    _wrong_topic(_folder(root, WEI) / PKG)
    _folder(root, GUS).mkdir(parents=True)
    (_folder(root, GUS) / 'notes.txt').write_text('I will hand it in later\n')
    worksheet = root.parent / 'worksheet.csv'
    with worksheet.open('w', newline='', encoding='utf-8-sig') as f:
        csv.writer(f).writerows(WORKSHEET)
    out = root.parent / 'out'
    done = run_cli('grade', str(root), '--lab', 'ch6-lab1', '-o', str(out), '--jobs', '2',
                   '--roster', str(worksheet), '--due', DUE, timeout=1500)
    first = {'grades': (out / 'grades.csv').read_text(),
             'feedback': {p.name: p.read_bytes() for p in (out / 'feedback').iterdir()}}
    return {'root': root, 'out': out, 'done': done, 'worksheet': worksheet, 'first': first}


@pytest.fixture(scope='module')
def regraded(moodle_class: dict[str, object],
             tmp_path_factory: pytest.TempPathFactory) -> subprocess.CompletedProcess[str]:
    """Wei resubmits a fixed package; the rubric now gives the controller 4 points."""
    root, out = moodle_class['root'], moodle_class['out']
    assert isinstance(root, Path) and isinstance(out, Path)
    shutil.rmtree(_folder(root, WEI) / PKG)
    shutil.copytree(DATA / 'reference', _folder(root, WEI) / PKG)
    rubric = tmp_path_factory.mktemp('rubric') / 'ch6.yaml'
    text = run_cli('grade', '--print-rubric', '--lab', 'ch6-lab1').stdout
    rubric.write_text(text.replace('    name: A controller publishes commands derived from '
                                   'the sensor data\n    points: 2',
                                   '    name: A controller publishes commands derived from '
                                   'the sensor data\n    points: 4'))
    assert 'points: 4' in rubric.read_text()
    return run_cli('grade', str(root), '--rubric', str(rubric), '-o', str(out),
                   '--only', WEI, '--roster', str(moodle_class['worksheet']), '--due', DUE,
                   timeout=900)


def test_the_class_run_reports_everyone(moodle_class: dict[str, object]) -> None:
    done, out = moodle_class['done'], moodle_class['out']
    assert isinstance(done, subprocess.CompletedProcess) and isinstance(out, Path)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    rows = _rows(out)
    assert set(rows) == {ANA, JOSE, WEI, GUS}
    assert rows[ANA]['score'] == '13' and rows[ANA]['late_days'] == '0'
    assert rows[WEI]['score'] == '9'
    assert rows[GUS]['score'] == '0'
    last = done.stdout.strip().splitlines()[-1]
    short = sorted(r.student for r in load_record(out) if r.status != 'graded')
    assert last.startswith(f'4 student(s): {4 - len(short)} fully graded'), last
    assert all(f'{s} (' in last for s in short), last
    assert 'notes.txt is a .txt file, not a package' in (
        out / 'feedback' / 'Gus_Empty_1004.md').read_text()
    assert 'similarity.html' in done.stdout


def test_late_from_the_worksheet_time(moodle_class: dict[str, object]) -> None:
    out = moodle_class['out']
    assert isinstance(out, Path)
    jose = _rows(out)[JOSE]
    assert (jose['late_days'], jose['penalty'], jose['score']) == ('2', '2.6', '10.4')
    assert _rows(out)[WEI]['late_days'] == '0'  # 11:58 PM: a minute early
    page = (out / 'feedback' / 'José_Núñez_1002.md').read_text()
    assert 'Handed in 2 day(s) late (2026-11-22 09:05): 2.6 point(s) off the 13 earned.' in page


def test_the_worksheet_is_written_back_ready_to_import(moodle_class: dict[str, object]) -> None:
    done, out = moodle_class['done'], moodle_class['out']
    assert isinstance(done, subprocess.CompletedProcess) and isinstance(out, Path)
    back = _csv(out / 'moodle-grades.csv')
    assert back[0] == WORKSHEET[0]
    assert (out / 'moodle-grades.csv').read_bytes().startswith(b'\xef\xbb\xbf')
    by_id = {row[0]: row for row in back[1:]}
    assert by_id['Participant 1001'][4] == '100.00'
    assert by_id['Participant 1002'][4] == '80.00'  # 10.4/13 after the late penalty
    assert by_id['Participant 1003'][4] == '69.23'
    assert by_id['Participant 1004'][4] == '0.00'
    assert by_id['Participant 1004'][9].startswith('0/13. No check met')
    assert by_id['Participant 1005'][4] == ''  # no hand-in: left for the instructor
    assert by_id['Participant 1003'][9].startswith(
        '9/13. Not met: controller_commands, actuator_logs.')
    assert 'Late 2 day(s): -2.6.' in by_id['Participant 1002'][9]
    assert [row[:4] for row in back] == [row[:4] for row in WORKSHEET]  # identity untouched
    assert 'in the roster but not graded (1): Lena Absent (Participant 1005)' in done.stdout


def test_summary_page(moodle_class: dict[str, object]) -> None:
    out = moodle_class['out']
    assert isinstance(out, Path)
    page = (out / 'summary.html').read_text()
    picture = re.search(r'src="data:image/png;base64,([^"]+)"', page)
    assert picture and base64.b64decode(picture.group(1))[:4] == b'\x89PNG'
    checks = dict(re.findall(r'<tr><td>(\w+)</td><td>[^<]*</td><td>(\d+/\d+)</td>', page))
    assert checks['builds'] == '3/4' and checks['controller_commands'] == '2/4'
    zero = page[page.index('id="zero"'):page.index('id="not-graded"')]
    assert GUS in zero and ANA not in zero
    short = page[page.index('id="not-graded"'):page.index('id="missing"')]
    assert all(r.student in short for r in load_record(out) if r.status != 'graded')
    assert 'Lena Absent (Participant 1005)' in page[page.index('id="missing"'):]
    late = page[page.index('id="late"'):page.index('id="slowest"')]
    assert '<td>José Núñez_1002</td><td>2026-11-22 09:05</td><td>2</td><td>2.6</td>' in late
    slowest = page[page.index('id="slowest"'):]
    assert slowest.count('<tr><td>') == 4 and ' s</td>' in slowest


def test_only_replaces_one_row_and_prints_the_change(
        moodle_class: dict[str, object], regraded: subprocess.CompletedProcess[str]) -> None:
    out, first = moodle_class['out'], moodle_class['first']
    assert isinstance(out, Path) and isinstance(first, dict)
    assert regraded.returncode == 0, regraded.stdout[-3000:] + regraded.stderr[-3000:]
    assert f'scores changed since the last run: {WEI} 9/13 → 15/15' in regraded.stdout
    assert '(1 regraded, merged into 4)' in regraded.stdout
    assert 'similarity.html' not in regraded.stdout  # one student: nothing compared
    rows = _rows(out)
    assert rows[WEI]['score'] == rows[WEI]['max_score'] == '15'
    before = {r['student']: r for r in csv.DictReader(io.StringIO(first['grades']))}
    for student in (ANA, JOSE, GUS):
        assert rows[student] == before[student]
    for name, content in first['feedback'].items():
        if not name.startswith('Wei_Chen'):
            assert (out / 'feedback' / name).read_bytes() == content, name
    assert (out / 'feedback' / 'Wei_Chen_1003.md').read_bytes() != first['feedback'][
        'Wei_Chen_1003.md']
    back = {row[0]: row for row in _csv(out / 'moodle-grades.csv')[1:]}
    assert back['Participant 1003'][4] == '100.00'
    assert back['Participant 1001'][4] == '100.00'  # still there, from the record


def test_canvas_export_filled_from_the_record(
        moodle_class: dict[str, object], regraded: subprocess.CompletedProcess[str],
        tmp_path: Path) -> None:
    """The same reports as a Canvas class: matched by the user id in Canvas's file names,
    the LATE mark applied, the assignment column filled, every other cell kept."""
    out = moodle_class['out']
    assert isinstance(out, Path)
    reports = {r.student: r for r in load_record(out)}
    export = tmp_path / 'canvas.csv'
    export.write_text(
        'Student,ID,SIS User ID,SIS Login ID,Section,Lab 1 (3301),Lab 6.1 (3302),'
        'Current Score\n'
        '    Points Possible,,,,,10,20,(read only)\n'
        '"Lima, Ana",501,S501,alima,A,8,,90\n'
        '"Chen, Wei",503,S503,wchen,A,7,,70\n'
        '"Student, Test",999,,,A,,,\n')
    sources = {'alima': 'alima_501_9001_robot_system.zip',
               'wchen': 'wchen_LATE_503_9003_robot_system.zip',
               'gus': 'gus_504_9004_notes.txt'}
    ana, wei, gus = reports[ANA], reports[WEI], reports[GUS]
    ana.student, wei.student, gus.student = 'alima', 'wchen', 'gus'
    LatePolicy(parse_due(DUE), 0.1).apply(
        [ana, wei], {'wchen': Submitted(late_mark=True), 'alima': Submitted()})
    assert (wei.late_days, wei.penalty) == (1, 1.5)
    roster = read_roster(export, lab='lab 6.1')
    result = roster.fill([ana, wei, gus], sources, tmp_path / 'canvas-grades.csv')
    rows = list(csv.reader((tmp_path / 'canvas-grades.csv').open()))
    assert rows[0] == ['Student', 'ID', 'SIS User ID', 'SIS Login ID', 'Section',
                       'Lab 1 (3301)', 'Lab 6.1 (3302)', 'Current Score']
    assert rows[1][0] == '    Points Possible'
    assert rows[2][5:] == ['8', '20.00', '90']  # 13/13 of 20 points; Lab 1 kept
    assert rows[3][5:] == ['7', '18.00', '70']  # 15 - 1.5 late = 13.5/15 of 20
    assert result.only_graded == ['gus']
    assert result.only_roster == ['Student, Test (999)']
