"""Notebook 07's answer cells: what a student's copy keeps around each answer.

That its answers earn full marks from the instructor's grader is checked where the notebook
runs from an empty workspace anyway: tests/test_mistake_path_capstone.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytestmark = pytest.mark.no_ros  # reads the notebook only: no ROS_DOMAIN_ID slot

NOTEBOOK = Path(__file__).resolve().parents[1] / 'notebooks' / '07_capstone.ipynb'


@pytest.mark.parametrize('cell_id', ['nb07_sensor', 'nb07_controller', 'nb07_actuator'])
def test_capstone_answer_cells_keep_a_scaffold_outside_the_answer(cell_id: str) -> None:
    """What a student copy keeps: the class, its __init__ and main(), answers fenced."""
    cells = json.loads(NOTEBOOK.read_text())['cells']
    (cell,) = [c for c in cells if c.get('id') == cell_id]
    outside = []
    inside = False
    for line in ''.join(cell['source']).splitlines():
        if '### BEGIN SOLUTION' in line:
            inside = True
        elif '### END SOLUTION' in line:
            inside = False
        elif not inside:
            outside.append(line)
    kept = '\n'.join(outside)
    assert 'class ' in kept and 'def main(' in kept and 'super().__init__(' in kept
    assert cell['metadata']['nbgrader']['solution'] is True
