"""The browser course's nbval comparison (output_check.py) fails where nbval would."""

from __future__ import annotations

import json
from pathlib import Path

import output_check
import pytest

pytestmark = pytest.mark.no_ros
NOTEBOOK = output_check.REPO / 'notebooks' / '05_inspect_and_verify.ipynb'


def _first_checked_stream(notebook: dict[str, object]) -> dict[str, object]:
    cells = notebook['cells']
    assert isinstance(cells, list)
    return next(o for c in cells if c['cell_type'] == 'code'
                and '# NBVAL_CHECK_OUTPUT' in ''.join(c['source'])
                for o in c['outputs'] if o['output_type'] == 'stream')


def test_the_committed_notebook_matches_itself() -> None:
    assert output_check.mismatches(NOTEBOOK, NOTEBOOK) == []


def test_a_changed_checked_output_is_named(tmp_path: Path) -> None:
    notebook = json.loads(NOTEBOOK.read_text())
    _first_checked_stream(notebook)['text'] = ['✓ 2 nodes running: /robot, /sensor\n']
    ran = tmp_path / 'ran.ipynb'
    ran.write_text(json.dumps(notebook))
    [problem] = output_check.mismatches(ran, NOTEBOOK)
    assert 'output differs' in problem and '+✓ 2 nodes running' in problem, problem


def test_line_ends_and_fast_dds_noise_are_not_differences(tmp_path: Path) -> None:
    notebook = json.loads(NOTEBOOK.read_text())
    stream = _first_checked_stream(notebook)
    text = ''.join(stream['text'])  # type: ignore[arg-type]
    stream['text'] = text.replace('\n', '\r\n') + (
        '2026-11-27 [RTPS_TRANSPORT_SHM Error] Failed init_port fastrtps_port7411\n')
    ran = tmp_path / 'ran.ipynb'
    ran.write_text(json.dumps(notebook))
    assert output_check.mismatches(ran, NOTEBOOK) == []
