"""The course's own packages (Lab 1.3, Chapter 6) as test fixtures: copy, fix, colcon build.

tests/data/seeds/ holds each package exactly as its lab writes it (indentation restored).
Two of the seed's mistakes can be fixed on copy, so tests can show both the error a
student meets and the working package:
- Lab 1.3's package.xml has no `<export><build_type>ament_python</build_type></export>`,
  so colcon takes it for ament_cmake and fails;
- Lab 1.3's config/robot_params.yaml is flat, which rcl refuses (`Cannot have a value
  before ros__parameters`); nested under `/**: ros__parameters:` it loads.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

__all__ = [
    'CH6',
    'LAB13',
    'LAB13_EXPECTED_LINES',
    'SEEDS',
    'add_build_type',
    'colcon_build',
    'copy_seed',
    'nest_param_file',
    'workspace_env',
]

SEEDS = Path(__file__).resolve().parent / 'data' / 'seeds'
LAB13 = SEEDS / 'lab13' / 'my_robot_system'
CH6 = SEEDS / 'ch6' / 'robot_controller'
COLCON = Path(sys.executable).parent / 'colcon'

# Lab 1.3 Part 7's expected output with robot_name:=robot_alpha, as `ros2 launch` prints it.
LAB13_EXPECTED_LINES = [
    r'^\[sensor_node-1\] \[INFO\] \[[\d.]+\] \[sensor\]: Sensor node started \(rate: 10 Hz\)$',
    r'^\[controller_node-2\] \[INFO\] \[[\d.]+\] \[controller\]: Controller node started$',
    r'^\[robot_node-3\] \[INFO\] \[[\d.]+\] \[robot\]: Robot node started: robot_alpha$',
    r'^\[robot_node-3\] \[INFO\] \[[\d.]+\] \[robot\]: Status: OK \(temp: 22\.\d°C\)$',
]

_BUILD_TYPE = '  <export>\n    <build_type>ament_python</build_type>\n  </export>\n'


def add_build_type(package_xml: Path) -> None:
    """Add the ament_python build type `ros2 pkg create --build-type` would have written."""
    text = package_xml.read_text()
    if '<build_type>' in text:
        return
    package_xml.write_text(text.replace('</package>', _BUILD_TYPE + '</package>'))


def nest_param_file(path: Path, node: str = '/**') -> None:
    """Rewrite a flat parameter file under `<node>: ros__parameters:` (comments kept)."""
    lines = path.read_text().splitlines()
    nested = [f'{node}:', '  ros__parameters:']
    nested += [('    ' + line) if line.strip() else '' for line in lines]
    path.write_text('\n'.join(nested) + '\n')


def copy_seed(seed: Path, workspace: Path, *, build_type: bool = True,
              nest_params: bool = True) -> Path:
    """Copy a seed package to `workspace/src/<name>`, with or without the two fixes."""
    dest = workspace / 'src' / seed.name
    shutil.copytree(seed, dest)
    if build_type:
        add_build_type(dest / 'package.xml')
    if nest_params:
        for yaml_file in sorted((dest / 'config').glob('*.yaml')):
            if 'ros__parameters' not in yaml_file.read_text():
                nest_param_file(yaml_file)
    return dest


def colcon_build(workspace: Path, *, timeout: float = 300.0,
                 extra: list[str] | None = None) -> subprocess.CompletedProcess[str]:
    """`colcon build --base-paths src` in `workspace` with the venv's colcon; raises on failure."""
    cmd = [str(COLCON), 'build', '--base-paths', 'src', *(extra or [])]
    env = dict(os.environ)
    env['PATH'] = f'{COLCON.parent}{os.pathsep}{env.get("PATH", "")}'
    result = subprocess.run(cmd, cwd=workspace, env=env, capture_output=True, text=True,
                            timeout=timeout, check=False)
    if result.returncode != 0:
        raise RuntimeError(
            f'colcon build failed in {workspace} (exit {result.returncode}):\n'
            f'{result.stdout[-3000:]}\n{result.stderr[-3000:]}'
        )
    return result


def workspace_env(workspace: Path) -> dict[str, str]:
    """The variables `source install/setup.bash` sets (AMENT_PREFIX_PATH, PYTHONPATH, ...)."""
    setup = workspace / 'install' / 'setup.bash'
    script = f'source {setup} >/dev/null 2>&1 && env -0'
    out = subprocess.run(['bash', '-c', script], capture_output=True, check=True,
                         env=dict(os.environ), timeout=60)
    sourced = dict(
        item.split('=', 1) for item in out.stdout.decode().split('\0') if '=' in item
    )
    keys = ('AMENT_PREFIX_PATH', 'PYTHONPATH', 'PATH', 'LD_LIBRARY_PATH', 'COLCON_PREFIX_PATH')
    return {k: sourced[k] for k in keys if k in sourced and sourced[k] != os.environ.get(k)}
