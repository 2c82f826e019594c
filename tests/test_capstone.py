"""Notebook 07's promise: its answers, run from an empty workspace, earn full marks.

The notebook (the source, with its answers) runs in a fresh robot_lab kernel with
ROBOT_LAB_WORKSPACE set to an empty folder, up to where it grades itself; then the
instructor's grader, `robot-lab grade --lab ch6-lab1`, grades the package it left there.
The notebook's own grading cells are not trusted for this: the grader runs here, apart.
"""

from __future__ import annotations

import csv
import json
import os
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import run_cli

NOTEBOOK = Path(__file__).resolve().parents[1] / 'notebooks' / '07_capstone.ipynb'
PACKAGE = 'multi_node_robot'


def _until_grading(notebook: Any) -> Any:
    """The notebook up to its section 10 (where it grades itself)."""
    cells = notebook.cells
    stop = next(i for i, c in enumerate(cells)
                if c.cell_type == 'markdown' and c.source.startswith('## 10.'))
    notebook.cells = cells[:stop]
    return notebook


def test_capstone_source_leaves_a_package_with_full_marks(tmp_path: Path,
                                                          ros_domain: int) -> None:
    import nbformat
    from nbclient import NotebookClient

    workspace = tmp_path / 'empty_ws'
    workspace.mkdir()
    env_before = dict(os.environ)
    os.environ.update({
        'ROBOT_LAB_WORKSPACE': str(workspace),
        'ROBOT_LAB_HEADLESS': '1',
        # lesson 07 gets domain base + 7: this module's own domain
        'ROBOT_LAB_NOTEBOOK_DOMAIN_BASE': str(ros_domain - 7),
        'PATH': os.pathsep.join([os.path.dirname(sys.executable), os.environ['PATH']]),
    })
    try:
        notebook = _until_grading(nbformat.read(NOTEBOOK, as_version=4))  # type: ignore[no-untyped-call]
        NotebookClient(notebook, timeout=120, kernel_name='robot_lab',
                       resources={'metadata': {'path': str(tmp_path)}}).execute()
    finally:
        os.environ.clear()
        os.environ.update(env_before)

    package = workspace / 'src' / PACKAGE
    assert (package / 'package.xml').is_file(), 'the notebook left no package'
    out = tmp_path / 'report'
    result = run_cli('grade', str(package), '--lab', 'ch6-lab1', '-o', str(out),
                     '--domain-id', str(ros_domain), timeout=240)
    assert result.returncode == 0, result.stdout + result.stderr
    with (out / 'grades.csv').open(newline='') as f:
        (row,) = list(csv.DictReader(f))
    scores = json.loads((out / 'results' / f'{row["student"]}.json').read_text())
    lost = [t['name'] for t in scores['tests'] if t['score'] < t['max_score']]
    feedback = (out / 'feedback' / f'{row["student"]}.md').read_text()
    assert not lost and float(row['score']) == float(row['max_score']), \
        f'checks that lost points: {lost}\n{feedback}'


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
