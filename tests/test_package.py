"""The repository is itself a valid ament_python package that real colcon builds."""

from __future__ import annotations

import os
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

from conftest import BIN, REPO, venv_env


def _tracked_copy(dest: Path) -> None:
    """Copy the files git tracks (what a clone has), not the developer's build leftovers."""
    files = subprocess.run(['git', 'ls-files'], cwd=REPO, capture_output=True, text=True,
                           check=True).stdout.split()
    for name in files:
        src = REPO / name
        if src.is_file():
            target = dest / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, target)


def test_package_xml_is_format3_ament_python() -> None:
    root = ET.parse(REPO / 'package.xml').getroot()
    assert root.tag == 'package' and root.get('format') == '3'
    assert root.findtext('name') == 'robot_lab'
    assert root.findtext('export/build_type') == 'ament_python'
    assert (REPO / 'resource' / 'robot_lab').is_file()


def test_colcon_build_installs_nodes_launch_and_config(tmp_path: Path) -> None:
    _tracked_copy(tmp_path / 'src' / 'robot_lab')
    env = venv_env()
    res = subprocess.run([str(BIN / 'colcon'), 'build', '--base-paths', 'src'], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=300, check=False)
    assert res.returncode == 0, res.stdout + res.stderr
    prefix = tmp_path / 'install' / 'robot_lab'
    for node in ('sensor_node', 'controller_node', 'robot_node'):
        exe = prefix / 'lib' / 'robot_lab' / node
        assert exe.is_file() and os.access(exe, os.X_OK), exe
    share = prefix / 'share' / 'robot_lab'
    assert (share / 'package.xml').is_file()
    assert (share / 'config' / 'robot_params.yaml').is_file()
    assert (share / 'launch' / 'robot.launch.xml').is_file()
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    assert (index / 'robot_lab').is_file()
    # What `source install/setup.bash` gives: the built package wins over the kit's own.
    out = subprocess.run(
        ['bash', '-c', 'source install/setup.bash && python -c '
         '"from robot_lab.pkg.index import package_prefix; print(package_prefix(\'robot_lab\'))"'],
        cwd=tmp_path, env=env, capture_output=True, text=True, check=False)
    assert str(prefix) in out.stdout
