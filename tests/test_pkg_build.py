"""robot-lab build runs the real colcon; the built package runs after `source
install/setup.bash` or use_workspace(); rebuilds take effect at the next run; failures
show the failing package and the lines that explain it."""

from __future__ import annotations

import contextlib
import importlib
import io
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import BIN, REPO, run_cli
from seeds import LAB13, copy_seed

from robot_lab.errors import PackageError
from robot_lab.pkg import workspace
from robot_lab.pkg.build import build
from robot_lab.pkg.create import create_package
from robot_lab.pkg.index import find_executable
from robot_lab.pkg.workspace import use_workspace, workspace_dir

CREATE = ('pkg', 'create', '--build-type', 'ament_python', 'demo_pkg',
          '--dependencies', 'rclpy', 'std_msgs', '--node-name', 'talker')


@pytest.fixture(scope='module')
def demo_ws(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The acceptance workspace: pkg create in src/, then `robot-lab build` (one build)."""
    ws = tmp_path_factory.mktemp('demo_ws')
    (ws / 'src').mkdir()
    created = run_cli(*CREATE, cwd=ws / 'src')
    assert created.returncode == 0, created.stderr
    built = run_cli('build', cwd=ws, timeout=240)
    assert built.returncode == 0, built.stdout + built.stderr
    return ws, built.stdout


@pytest.fixture
def isolated_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """use_workspace changes os.environ and sys.path: undo it after each test."""
    for name in ('AMENT_PREFIX_PATH', 'PYTHONPATH'):
        if name in os.environ:
            monkeypatch.setenv(name, os.environ[name])
        else:
            monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(sys, 'path', list(sys.path))
    monkeypatch.setattr(workspace, '_used', [])
    modules = set(sys.modules)
    yield
    for name in set(sys.modules) - modules:
        if name.split('.')[0] in ('demo_pkg', 'edit_pkg', 'link_pkg'):
            del sys.modules[name]


def _shell_env() -> dict[str, str]:
    """A student's shell: the venv on PATH, nothing of any workspace sourced yet."""
    env = {k: v for k, v in os.environ.items() if k not in ('AMENT_PREFIX_PATH', 'PYTHONPATH')}
    env['PATH'] = f'{BIN}{os.pathsep}{env.get("PATH", "")}'
    return env


def _sourced(ws: Path) -> dict[str, str]:
    """AMENT_PREFIX_PATH and PYTHONPATH as `source install/setup.bash` leaves them."""
    out = subprocess.run(
        ['bash', '-c', 'source install/setup.bash && '
         'printf "%s\\n%s\\n" "$AMENT_PREFIX_PATH" "$PYTHONPATH"'],
        cwd=ws, env=_shell_env(), capture_output=True, text=True, check=True, timeout=60,
    ).stdout.splitlines()
    return {'AMENT_PREFIX_PATH': out[0], 'PYTHONPATH': out[1]}


def _call_main(module: str) -> str:
    mod = importlib.import_module(module)
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        mod.main()
    return buffer.getvalue().strip()


def test_build_reports_colcon_progress(demo_ws: tuple[Path, str]) -> None:
    ws, output = demo_ws
    lines = output.splitlines()
    assert 'Starting >>> demo_pkg' in lines
    assert any(line.startswith('Finished <<< demo_pkg [') for line in lines)
    assert any(line.startswith('Summary: 1 package finished') for line in lines)
    assert (ws / 'install' / 'setup.bash').is_file()
    talker = ws / 'install' / 'demo_pkg' / 'lib' / 'demo_pkg' / 'talker'
    assert talker.is_file() and os.access(talker, os.X_OK)
    marker = ws / 'install' / 'demo_pkg' / 'share' / 'ament_index' / 'resource_index'
    assert (marker / 'packages' / 'demo_pkg').is_file()


def test_source_setup_bash_then_robot_lab_run(demo_ws: tuple[Path, str]) -> None:
    """What students type: `source install/setup.bash && robot-lab run demo_pkg talker`."""
    ws, _ = demo_ws
    for verb in ('robot-lab', 'ros2'):
        result = subprocess.run(
            ['bash', '-c', f'source install/setup.bash && {verb} run demo_pkg talker'],
            cwd=ws, env=_shell_env(), capture_output=True, text=True, timeout=60, check=False,
        )
        assert result.returncode == 0, result.stderr
        assert result.stdout == 'Hi from demo_pkg.\n'


def test_run_with_the_sourced_environment(demo_ws: tuple[Path, str]) -> None:
    ws, _ = demo_ws
    result = run_cli('run', 'demo_pkg', 'talker', env=_sourced(ws))
    assert result.returncode == 0, result.stderr
    assert result.stdout == 'Hi from demo_pkg.\n'
    executables = run_cli('pkg', 'executables', 'demo_pkg', env=_sourced(ws))
    assert executables.stdout == 'demo_pkg talker\n'


def test_not_found_before_sourcing(demo_ws: tuple[Path, str]) -> None:
    result = subprocess.run([str(BIN / 'robot-lab'), 'run', 'demo_pkg', 'talker'],
                            env=_shell_env(), capture_output=True, text=True, timeout=60,
                            check=False)
    assert result.returncode == 1
    assert "Package 'demo_pkg' not found" in result.stderr
    assert 'source install/setup.bash' in result.stderr


@pytest.mark.usefixtures('isolated_env')
def test_use_workspace_is_source_setup_bash(demo_ws: tuple[Path, str]) -> None:
    ws, _ = demo_ws
    sourced = _sourced(ws)
    os.environ.pop('PYTHONPATH', None)
    prefixes = use_workspace(ws)
    assert prefixes == [ws / 'install' / 'demo_pkg']
    assert os.environ['AMENT_PREFIX_PATH'].split(os.pathsep)[0] == \
        sourced['AMENT_PREFIX_PATH'].split(os.pathsep)[0] == str(prefixes[0])
    assert os.environ['PYTHONPATH'] == sourced['PYTHONPATH']
    assert find_executable('demo_pkg', 'talker') == prefixes[0] / 'lib' / 'demo_pkg' / 'talker'
    assert _call_main('demo_pkg.talker') == 'Hi from demo_pkg.'  # importable in-process
    result = run_cli('run', 'demo_pkg', 'talker')  # children inherit it
    assert result.stdout == 'Hi from demo_pkg.\n', result.stderr
    use_workspace(ws / 'install')  # the install folder itself works too, idempotently
    assert os.environ['AMENT_PREFIX_PATH'].split(os.pathsep).count(str(prefixes[0])) == 1


@pytest.mark.usefixtures('isolated_env')
def test_rebuild_takes_effect_without_restart(tmp_path: Path) -> None:
    create_package('edit_pkg', tmp_path / 'src', node_name='talker')
    first = build(tmp_path, progress=False)
    assert first.ok, str(first)
    assert first.finished == ['edit_pkg'] and first.packages == {'edit_pkg': 'ros.ament_python'}
    use_workspace(tmp_path)
    assert _call_main('edit_pkg.talker') == 'Hi from edit_pkg.'
    node = tmp_path / 'src' / 'edit_pkg' / 'edit_pkg' / 'talker.py'
    node.write_text(node.read_text().replace('Hi from', 'Hello again from'))
    second = build(tmp_path, packages_select=['edit_pkg'], progress=False)
    assert second.ok, str(second)
    # build() re-applied the workspace in use: the next import and the next run see it.
    assert _call_main('edit_pkg.talker') == 'Hello again from edit_pkg.'
    result = run_cli('run', 'edit_pkg', 'talker')
    assert result.stdout == 'Hello again from edit_pkg.\n', result.stderr


@pytest.mark.usefixtures('isolated_env')
def test_symlink_install_sees_edits_without_rebuild(tmp_path: Path) -> None:
    create_package('link_pkg', tmp_path / 'src', node_name='talker')
    result = run_cli('build', str(tmp_path), '--symlink-install', timeout=240)
    assert result.returncode == 0, result.stdout + result.stderr
    use_workspace(tmp_path)
    assert run_cli('run', 'link_pkg', 'talker').stdout == 'Hi from link_pkg.\n'
    node = tmp_path / 'src' / 'link_pkg' / 'link_pkg' / 'talker.py'
    node.write_text(node.read_text().replace('Hi from', 'Edited'))
    assert run_cli('run', 'link_pkg', 'talker').stdout == 'Edited link_pkg.\n'


def test_failed_build_shows_the_setup_py_error(tmp_path: Path) -> None:
    pkg = create_package('broken_pkg', tmp_path / 'src', node_name='talker')
    setup_py = pkg / 'setup.py'
    setup_py.write_text(setup_py.read_text().replace('setup(\n', 'raise_me()\nsetup(\n', 1))
    bad_line = setup_py.read_text().splitlines().index('raise_me()') + 1
    result = run_cli('build', cwd=tmp_path, timeout=240)
    assert result.returncode == 1
    assert 'Failed   <<< broken_pkg' in result.stdout
    report = result.stderr.split('--- broken_pkg failed ---\n', 1)[1]
    section = report.split('(full log:')[0].splitlines()
    assert section == [
        'Traceback (most recent call last):',
        f'  File "{setup_py}", line {bad_line}, in <module>',
        '    raise_me()',
        "NameError: name 'raise_me' is not defined",
        f'hint: robot-lab doctor {pkg} checks the package files',
    ]
    assert f'(full log: {tmp_path / "log" / "latest_build" / "broken_pkg"})' in report
    assert '1 package failed: broken_pkg' in report


def test_failed_build_shows_the_setuptools_error(tmp_path: Path) -> None:
    pkg = create_package('markerless_pkg', tmp_path / 'src')
    (pkg / 'resource' / 'markerless_pkg').unlink()
    result = build(tmp_path, progress=False)
    assert not result.ok
    assert result.failed == ['markerless_pkg']
    assert result.errors['markerless_pkg'] == [
        "error: can't copy 'resource/markerless_pkg': doesn't exist or not a regular file",
    ]
    assert f'robot-lab doctor {pkg} checks the package files' in result.hints['markerless_pkg']


def test_seed_package_xml_without_build_type_fails_with_the_reason(tmp_path: Path) -> None:
    copy_seed(LAB13, tmp_path, build_type=False, nest_params=False)
    result = build(tmp_path, progress=False)
    assert not result.ok
    assert result.failed == ['my_robot_system']
    assert result.packages['my_robot_system'] != 'ros.ament_python'
    assert result.errors['my_robot_system']
    assert any('<build_type>ament_python</build_type>' in hint
               for hint in result.hints['my_robot_system'])
    assert 'hint: colcon built my_robot_system as a CMake package' in str(result)


def test_packages_select_of_an_unknown_package(demo_ws: tuple[Path, str]) -> None:
    ws, _ = demo_ws
    result = run_cli('build', '--packages-select', 'demo_pgk', cwd=ws, timeout=120)
    assert result.returncode == 1
    assert "--packages-select: no package named 'demo_pgk'" in result.stderr
    assert 'packages found: demo_pkg' in result.stderr


def test_build_refuses_a_package_folder_and_a_missing_workspace(
    demo_ws: tuple[Path, str], tmp_path: Path
) -> None:
    ws, _ = demo_ws
    with pytest.raises(PackageError, match='is a package, not a workspace'):
        build(ws / 'src' / 'demo_pkg', progress=False)
    missing = run_cli('build', str(tmp_path / 'nowhere'))
    assert missing.returncode == 1
    assert 'does not exist' in missing.stderr


def test_use_workspace_before_a_build(tmp_path: Path) -> None:
    with pytest.raises(PackageError, match='has not been built'):
        use_workspace(tmp_path)


def test_workspace_dir(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv('ROBOT_LAB_WORKSPACE', str(tmp_path / 'ws'))
    assert workspace_dir() == tmp_path / 'ws'
    assert (tmp_path / 'ws' / 'src').is_dir()
    monkeypatch.delenv('ROBOT_LAB_WORKSPACE')
    monkeypatch.setenv('HOME', str(tmp_path))
    assert workspace_dir(create=False) == tmp_path / 'robot_lab_ws'
    monkeypatch.setenv('ROBOT_LAB_WORKSPACE', str(REPO / 'ws'))
    with pytest.raises(PackageError, match='inside the robot_lab repository'):
        workspace_dir()
    assert not (REPO / 'ws').exists()


def test_kill_int_stops_a_background_ros2_run_before_its_node_is_up(tmp_path: Path) -> None:
    """bash starts a script's background jobs with SIGINT ignored, and the ignore survives
    exec: a program run by `ros2 run … &` missed `kill -INT %1` until rclpy.init took the
    signal, and the script's `wait` hung (lesson 10, while the kit built turtlesim)."""
    prefix = tmp_path / 'install'
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    (index / 'slow_pkg').write_text('')
    exe = prefix / 'lib' / 'slow_pkg' / 'slow_start'
    exe.parent.mkdir(parents=True)
    exe.write_text(f'#!{sys.executable}\nimport time\nprint("importing", flush=True)\n'
                   'time.sleep(60)  # a node still importing: no rclpy.init yet\n')
    exe.chmod(0o755)
    script = ('ros2 run slow_pkg slow_start > started &\n'
              'until grep -q importing started; do sleep 0.05; done  # the program runs\n'
              'kill -INT %1; wait %1; echo "exit $?"\n')
    env = {**_shell_env(), 'AMENT_PREFIX_PATH': os.pathsep.join(
        [str(prefix), *filter(None, [os.environ.get('AMENT_PREFIX_PATH')])])}
    result = subprocess.run(['bash', '-c', script], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=30, check=False)
    assert result.stdout == 'exit 130\n', result.stderr
