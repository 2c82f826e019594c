"""The instructor's documents run as printed: every ```console block of docs/deploy.md, and
of the nbgrader section of docs/instructors.md (three simulated students: fetch, validate,
submit, collect, autograde, feedback, export), in a temporary folder."""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

import doc_console
import pytest
from conftest import BIN, REPO

from robot_lab.domain import DEFAULT_REGISTRY, HUB_REGISTRY


def _shell_env(home: Path) -> dict[str, str]:
    """A fresh login shell's environment with the kit's venv on PATH (no ROS variables)."""
    return {'PATH': f'{BIN}:/usr/bin:/bin', 'HOME': str(home), 'LANG': 'C.UTF-8',
            'USER': 'instructor', 'GIT_AUTHOR_NAME': 'instructor',
            'GIT_AUTHOR_EMAIL': 'instructor@example.org', 'GIT_COMMITTER_NAME': 'instructor',
            'GIT_COMMITTER_EMAIL': 'instructor@example.org',
            'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}


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


if __name__ == '__main__':  # pragma: no cover
    sys.exit(pytest.main([__file__, '-q', *os.environ.get('PYTEST_ARGS', '').split()]))
