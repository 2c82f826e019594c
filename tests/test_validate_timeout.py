"""nbgrader's Validate reports a cell that times out as a failure, in the kit's Lab.

nbgrader's Execute preprocessor interrupts a cell that runs past its timeout and goes on;
the timed-out cell gets an error output, but Validate only counts graded cells, so a hang
in any other cell ended in "Success! Your notebook passes all the tests." (seen on 01, whose
`ros2 run … | tail -n 1` ran for ever once 02 had written the node). The kit's nbgrader
config (config/jupyter/nbgrader_config.py, found through JUPYTER_CONFIG_PATH, which the
kit's server config sets) makes Validate stop at the timeout and fail, naming the cell.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import nbformat
import pytest
from conftest import BIN, REPO

PASSED = 'Success! Your notebook passes all the tests.'


@pytest.fixture
def hanging(tmp_path: Path) -> Path:
    """A notebook whose only graded cell passes, after a cell that outlives the timeout."""
    nb = nbformat.v4.new_notebook()  # type: ignore[no-untyped-call]
    nb.metadata['kernelspec'] = {'name': 'python3', 'display_name': 'Python 3',
                                 'language': 'python'}
    slow = nbformat.v4.new_code_cell('import time\ntime.sleep(60)')  # type: ignore[no-untyped-call]
    graded = nbformat.v4.new_code_cell('assert True')  # type: ignore[no-untyped-call]
    graded.metadata['nbgrader'] = {'grade': True, 'solution': False, 'locked': True,
                                   'grade_id': 'check', 'points': 1, 'schema_version': 3}
    nb.cells = [slow, graded]
    nbformat.write(nb, tmp_path / 'hang.ipynb')  # type: ignore[no-untyped-call]
    # a short timeout for the test (nbgrader's default is 30 s)
    (tmp_path / 'nbgrader_config.py').write_text('c = get_config()\nc.Execute.timeout = 3\n')
    return tmp_path


def _validate(folder: Path, config_path: str | None) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PATH=f'{BIN}{os.pathsep}{os.environ.get("PATH", "")}',
               JUPYTER_DATA_DIR=str(folder / '.jupyter-data'))
    env.pop('JUPYTER_CONFIG_PATH', None)
    if config_path is not None:
        env['JUPYTER_CONFIG_PATH'] = config_path
    return subprocess.run([str(BIN / 'nbgrader'), 'validate', 'hang.ipynb'], cwd=folder,
                          env=env, text=True, capture_output=True, timeout=120, check=False)


def test_nbgrader_alone_calls_a_timed_out_notebook_a_success(hanging: Path) -> None:
    done = _validate(hanging, None)
    assert PASSED in done.stdout, done.stdout + done.stderr


def test_the_kits_config_makes_validate_fail_on_a_timeout(hanging: Path) -> None:
    done = _validate(hanging, str(REPO / 'config' / 'jupyter'))
    assert PASSED not in done.stdout
    assert done.returncode != 0
    assert 'time.sleep(60)' in done.stdout + done.stderr  # it names the cell


def test_the_lab_reads_the_kits_nbgrader_config() -> None:
    # What the Validate button's handler reads: jupyter_config_path() at request time.
    from jupyter_core.paths import jupyter_config_path

    env = dict(os.environ)
    try:
        code = (REPO / 'config' / 'jupyter' / 'jupyter_server_config.py').read_text()
        exec(compile(code, 'jupyter_server_config.py', 'exec'),
             {'get_config': lambda: _Anything(), '__file__': str(
                 REPO / 'config' / 'jupyter' / 'jupyter_server_config.py')})
        assert str(REPO / 'config' / 'jupyter') in jupyter_config_path()
    finally:
        os.environ.clear()
        os.environ.update(env)


class _Anything:
    """A stand-in for traitlets' Config: any attribute, any value."""

    def __getattr__(self, name: str) -> _Anything:
        value = _Anything()
        object.__setattr__(self, name, value)
        return value
