"""How a grading job's report gets back to the grader (issue 51: one job once ended with
code 0 and "no readable report"). The job sends each report down a pipe; the grader keeps
the last complete line as report.json once every process of the job is gone. A process
that escaped the job's group keeps the pipe open and could rewrite report.json: it is
killed before the report is kept. A report that does not load says why (a kit changed
while a class is graded hands back a field this grader does not know)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from robot_lab.grading.package.containment import NO_SANDBOX_VAR
from robot_lab.grading.package.grade import _read_report
from robot_lab.grading.package.rubric import Limits, load_rubric
from robot_lab.grading.package.sandbox import REPORT_FD_VAR, run_job
from robot_lab.grading.report import CheckOutcome, StudentReport

RUBRIC = Path(__file__).resolve().parent.parent / 'robot_lab' / 'grading' / 'package' / \
    'rubrics' / 'ch6-lab1.yaml'

# The job: a child that leaves the job's process group holding the pipe (as a node forked
# without exec would) and rewrites report.json as soon as it appears; then the job's own
# report down the pipe, and exit 0.
JOB = f"""
import os, sys, time
from pathlib import Path
here = Path(sys.argv[-1])
fd = int(os.environ[{REPORT_FD_VAR!r}])
if os.fork() == 0:
    os.setsid()
    end = time.monotonic() + 60
    while time.monotonic() < end:
        if (here / 'report.json').exists():
            (here / 'report.json').write_text('tampered')
        time.sleep(0.005)
    os._exit(0)
os.write(fd, os.environ['REPORT'].encode() + b'\\n')
"""


def test_an_escaped_process_cannot_touch_the_kept_report(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    rubric = load_rubric(RUBRIC)
    sent = StudentReport('ana', [CheckOutcome(c.id, c.name, c.points, c.points)
                                 for c in rubric.checks], title=rubric.lab)
    monkeypatch.setenv(NO_SANDBOX_VAR, '1')  # no namespace to end the child with the job
    monkeypatch.setenv('REPORT', json.dumps(sent.to_dict()))
    (tmp_path / 'job.json').write_text('{}')
    run = run_job(tmp_path, 11, Limits(wall_seconds=60), 'tok-escaped-report',
                  argv=['-c', JOB])
    assert run.returncode == 0, run.output
    kept = _read_report(tmp_path, 'ana', rubric)
    assert kept.status == 'graded' and kept.score == sent.score == 13, kept.error


def test_a_report_from_a_changed_kit_says_why_it_is_not_read(tmp_path: Path) -> None:
    rubric = load_rubric(RUBRIC)
    data = StudentReport('ana', [], title=rubric.lab).to_dict()
    data['checks'] = [{'id': 'builds', 'name': 'b', 'score': 2, 'max_score': 2,
                       'a_field_of_a_newer_kit': ''}]
    (tmp_path / 'report.json').write_text(json.dumps(data))
    report = _read_report(tmp_path, 'ana', rubric)
    assert report.status == 'error'
    assert 'cannot read (TypeError' in report.error and 'kit changed' in report.error
    assert _read_report(tmp_path / 'none', 'ana', rubric).error == \
        'the grading job left no report'
