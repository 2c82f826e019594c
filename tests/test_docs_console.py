"""The instructor's documents run as printed: every ```console block of docs/deploy.md, and
of the nbgrader section of docs/instructors.md (three simulated students: fetch, validate,
submit, collect, autograde, feedback, export), in a temporary folder."""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import doc_console
import pytest
from conftest import BIN, JOB_POOLS, REPO

from robot_lab.domain import DEFAULT_REGISTRY, HUB_REGISTRY, JOB_POOL_VARIABLE


def _shell_env(home: Path) -> dict[str, str]:
    """A fresh login shell's environment with the kit's venv on PATH (no ROS variables)."""
    return {'PATH': f'{BIN}:/usr/bin:/bin', 'HOME': str(home), 'LANG': 'C.UTF-8',
            'USER': 'instructor', 'GIT_AUTHOR_NAME': 'instructor',
            'GIT_AUTHOR_EMAIL': 'instructor@example.org', 'GIT_COMMITTER_NAME': 'instructor',
            'GIT_COMMITTER_EMAIL': 'instructor@example.org',
            'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
            # its registries are its own: jobs lease the part of 215-232 kept for it
            JOB_POOL_VARIABLE: JOB_POOLS['docs_console']}


def _fingerprint(path: Path) -> str | None:
    return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else None


def test_deploy_md_runs_as_printed(tmp_path: Path) -> None:
    registries = {p: _fingerprint(p) for p in (DEFAULT_REGISTRY, HUB_REGISTRY)}
    problems = doc_console.run((REPO / 'docs' / 'deploy.md').read_text(), tmp_path,
                               _shell_env(tmp_path))
    assert problems == [], '\n\n'.join(problems)
    # The examples used their own registry, never the host's.
    assert {p: _fingerprint(p) for p in registries} == registries
    assert (tmp_path / 'try' / 'domains.json').is_file()


@pytest.mark.timeout(1800)
def test_instructors_nbgrader_loop_runs_as_printed(tmp_path: Path) -> None:
    """generate → release → fetch → validate → submit → collect → autograde → feedback →
    export, three students, as docs/instructors.md prints it."""
    text = doc_console.section((REPO / 'docs' / 'instructors.md').read_text(),
                               '### In nbgrader: the whole loop')
    registry = tmp_path / 'registry' / 'domains.json'
    env = {**_shell_env(tmp_path), 'ROBOT_LAB_DOMAIN_REGISTRY': str(registry)}
    problems = doc_console.run(text, tmp_path, env)
    assert problems == [], '\n\n'.join(problems)
    course = tmp_path / 'course'
    rows = (course / 'grades.csv').read_text().splitlines()
    scores = {r.split(',')[3]: float(r.split(',')[7]) for r in rows[1:]}
    assert scores == {'alice': 8.0, 'bob': 0.0, 'carol': 0.0}
    for student in scores:
        assert (course / 'feedback' / student / 'ex04' / 'ex04_parameters.html').is_file()
    assert list((tmp_path / 'alice' / 'ex04' / 'feedback').rglob('*.html'))
    # The autograder's kernels leased their domains and gave them back.
    assert json.loads(registry.read_text())['leases'] == {}
    # Feedback an instructor can upload: each failed check says why in wrapped lines, with
    # no traceback into the kit's code and no path of the grader's machine.
    page = (course / 'feedback' / 'carol' / 'ex04' / 'ex04_parameters.html').read_text()
    for leak in (str(REPO), 'site-packages', '/tmp/robot_lab_autograde', str(tmp_path)):
        assert leak not in page, leak
    autograded = json.loads((course / 'autograded' / 'carol' / 'ex04' /
                             'ex04_parameters.ipynb').read_text())
    errors = [o for c in autograded['cells'] for o in c.get('outputs', [])
              if o['output_type'] == 'error' and o['ename'] == 'CheckError']
    assert len(errors) == 3  # one per automatic check, each once
    for error in errors:
        assert all(len(line) <= 88 for line in error['traceback']), error['traceback']
        assert error['traceback'][0].startswith('CheckError: ✗ expected')

if __name__ == '__main__':  # pragma: no cover
    sys.exit(pytest.main([__file__, '-q', *os.environ.get('PYTEST_ARGS', '').split()]))
