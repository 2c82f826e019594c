"""The course notebooks: committed as a real run left them, and their checks really check.

The notebooks themselves run in Chromium, their marked cells compared as nbval compares them
(tests/browser; `pytest --nbval-lax notebooks/` without Chromium). Here, notebook 05's
verification checklist — the cells' own source, read from the notebook — runs against the
working system (and prints exactly the committed ✓ lines) and against broken systems,
where it must fail and say what is wrong.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import robot_lab
from robot_lab.grading import CheckError, check

NOTEBOOKS = Path(__file__).resolve().parents[1] / 'notebooks'
NAMES = ['00_welcome', '01_create_package', '02_write_nodes', '03_launch_files',
         '04_parameters', '05_inspect_and_verify', '06_ros_bags', '07_capstone', '08_debugging',
         '09_services_actions', '10_turtlesim', '11_tf2_turtlesim',
         '12_robot_description', '13_simulation']
MARK = '# NBVAL_CHECK_OUTPUT'


def _cells(name: str) -> list[dict[str, Any]]:
    cells: list[dict[str, Any]] = json.loads((NOTEBOOKS / f'{name}.ipynb').read_text())['cells']
    return cells


def _source(cell: dict[str, Any]) -> str:
    return ''.join(cell['source'])


def _stdout(cell: dict[str, Any]) -> str:
    return ''.join(''.join(o['text']) for o in cell.get('outputs', [])
                   if o['output_type'] == 'stream' and o['name'] == 'stdout')


def _checklist() -> list[dict[str, Any]]:
    """Notebook 05's checklist cells: the code cells of its section 8."""
    cells = _cells('05_inspect_and_verify')
    start = next(i for i, c in enumerate(cells) if _source(c).startswith('## 8.'))
    stop = next(i for i, c in enumerate(cells) if _source(c).startswith('## 9.'))
    return [c for c in cells[start:stop] if c['cell_type'] == 'code']


@pytest.mark.parametrize('name', NAMES)
def test_notebook_is_committed_with_a_passing_run(name: str) -> None:
    notebook = json.loads((NOTEBOOKS / f'{name}.ipynb').read_text())
    assert notebook['metadata']['kernelspec']['name'] == 'robot_lab'
    code = [c for c in notebook['cells'] if c['cell_type'] == 'code']
    assert code[0]['source'] and f"setup('{name}')" in _source(code[0]), \
        'the first code cell sets the lesson up'
    for cell in code:
        assert cell.get('execution_count'), f'{name}: a cell was never run:\n{_source(cell)}'
        errors = [o for o in cell.get('outputs', []) if o['output_type'] == 'error']
        assert not errors, f'{name}: committed with an error in:\n{_source(cell)}'
        if 'check.' in _source(cell) and 'except check.CheckError' not in _source(cell):
            # every check cell is compared by nbval, and shows only ✓ lines (a cell that
            # catches CheckError shows a failure on purpose: a break-it-and-see step)
            assert _source(cell).startswith(MARK), f'{name}: unmarked check cell:\n{_source(cell)}'
            lines = [ln for ln in _stdout(cell).splitlines() if ln.startswith(('✓', '✗'))]
            assert lines and all(ln.startswith('✓') for ln in lines), _source(cell)


def test_student_work_goes_to_the_scratch_workspace_not_the_repository() -> None:
    for name in NAMES:
        code = [c for c in _cells(name) if c['cell_type'] == 'code']
        # a lesson that `%cd`s into its workspace first may write relative to it
        in_workspace = '%cd -q {ws}' in _source(code[0])
        for cell in code:
            assert 'notebooks/' not in _source(cell), f'{name} writes into the repository'
            for target in re.findall(r'%%writefile (\S+)', _source(cell)):
                relative = not target.startswith(('/', '~', '..'))
                assert target.startswith('{') or (in_workspace and relative), \
                    f'{name}: %%writefile {target} is not under the lesson workspace'


def _launch_file(tmp_path: Path, name: str, sensor: str = '', controller: str = '',
                 with_controller: bool = True) -> Path:
    config = Path(robot_lab.package_share('robot_lab')) / 'config' / 'robot_params.yaml'
    nodes = [f'<node pkg="robot_lab" exec="sensor_node" name="sensor">'
             f'<param from="{config}"/>{sensor}</node>']
    if with_controller:
        nodes.append(f'<node pkg="robot_lab" exec="controller_node" name="controller">'
                     f'<param from="{config}"/>{controller}</node>')
    nodes.append('<node pkg="robot_lab" exec="robot_node" name="robot"/>')
    path = tmp_path / f'{name}.launch.xml'
    path.write_text('<launch>\n  ' + '\n  '.join(nodes) + '\n</launch>\n')
    return path


@pytest.fixture
def launched() -> Iterator[list[Any]]:
    handles: list[Any] = []
    yield handles
    for handle in handles:
        handle.shutdown()


def _run_checklist(system: Any) -> None:
    namespace = {'check': check, 'robot_lab': robot_lab, 'system': system}
    for cell in _checklist():
        exec(compile(_source(cell), '05_inspect_and_verify', 'exec'), namespace)


def test_checklist_passes_on_the_working_system_with_the_committed_output(
        tmp_path: Path, launched: list[Any], capsys: pytest.CaptureFixture[str]) -> None:
    system = robot_lab.launch(_launch_file(tmp_path, 'working'))
    launched.append(system)
    _run_checklist(system)
    expected = ''.join(_stdout(cell) for cell in _checklist())
    assert capsys.readouterr().out == expected


BROKEN = {
    # the launch forgot a node: the first check names it
    'no_controller': ({'with_controller': False}, r'missing /controller'),
    # a wrong rate in the parameter file: the rate check says how fast it really is (about
    # 3 Hz: a loaded CI host measured 2.9)
    'slow_sensor': ({'sensor': '<param name="sensor_rate" value="3"/>'},
                    r'/sensor/temperature at 8–12 Hz; observed it runs at '
                    r'(2\.[5-9]|3\.[0-4]), (2\.[5-9]|3\.[0-4]) Hz'),
    # a controller that is always HIGH: the status check shows what it saw instead
    'hot_controller': ({'controller': '<param name="temp_threshold" value="20.0"/>'},
                       r"with status OK; observed within 5 s the last one was \{'data': 'HIGH"),
}


@pytest.mark.parametrize('broken', list(BROKEN))
def test_checklist_fails_on_a_broken_system_and_says_why(
        broken: str, tmp_path: Path, launched: list[Any]) -> None:
    options, message = BROKEN[broken]
    system = robot_lab.launch(_launch_file(tmp_path, broken, **options))
    launched.append(system)
    system.wait_for(r'Robot node started', timeout=15)
    with pytest.raises(CheckError, match=message) as failure:
        _run_checklist(system)
    assert str(failure.value).startswith('✗ expected ')
    assert 'Try: ' in str(failure.value)


def test_debugging_handout_has_the_five_faults_and_a_fresh_copy_undoes_repairs(
        tmp_path: Path) -> None:
    """Notebook 08's package: doctor names three faults, the graph-only two are really there."""
    from robot_lab.grading.handouts import broken_package
    from robot_lab.pkg.doctor import check_package

    pkg = broken_package(tmp_path)
    errors = [f for f in check_package(pkg).findings if f.severity == 'error']
    where = sorted(f'{Path(f.file or "").name}:{f.line}' for f in errors)
    assert where == ['package.xml:16', 'robot_params.yaml:2', 'setup.py:11'], errors
    setup_py = (pkg / 'setup.py').read_text()
    assert 'sensor_node = ' in setup_py and 'robot_node = ' not in setup_py
    assert "'/robot/stauts'" in (pkg / 'broken_robot' / 'robot_node.py').read_text()
    (pkg / 'package.xml').write_text('repaired')
    assert broken_package(tmp_path) == pkg
    assert '<build_type>' not in (pkg / 'package.xml').read_text()


def test_a_robot_that_never_stopped_names_both_causes(tmp_path: Path) -> None:
    """Notebook 06: no /cmd_vel of 0.0 in the bag is a change outside the recording, or
    nodes that ignore a parameter change (notebook 04's callbacks missing)."""
    from geometry_msgs.msg import Twist
    from rclpy.serialization import serialize_message

    from robot_lab.bag.writer import BagWriter, TopicSpec

    writer = BagWriter(tmp_path / 'run1', 'mcap')
    conn = writer.add_topic(TopicSpec('/cmd_vel', 'geometry_msgs/msg/Twist', []))
    for i in range(20):
        moving = Twist()
        moving.linear.x = 0.5
        writer.write(conn, 1_000_000_000 + i * 100_000_000, serialize_message(moving))
    writer.close()
    with pytest.raises(CheckError) as failure:
        check.first_time(tmp_path / 'run1', '/cmd_vel', 'linear.x', lambda v: v == 0.0, None)
    said = str(failure.value)
    assert 'none of its 20 messages does' in said
    assert 'inside the recording' in said and 'notebook 04' in said, said
