"""robot-lab pkg create writes what `ros2 pkg create --build-type ament_python` writes and
prints; refuses what it refuses; pkg list/prefix/executables (ament_cmake:
tests/test_custom_interfaces.py)."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from conftest import run_cli

from robot_lab.errors import PackageError
from robot_lab.params import load_param_file
from robot_lab.pkg.create import create_package
from robot_lab.pkg.doctor import doctor

CREATE = ('pkg', 'create', '--build-type', 'ament_python', 'demo_pkg',
          '--dependencies', 'rclpy', 'std_msgs', '--node-name', 'talker',
          '--maintainer-name', 'Ada', '--maintainer-email', 'ada@example.com')

PACKAGE_XML = """\
<?xml version="1.0"?>
<?xml-model href="http://download.ros.org/schema/package_format3.xsd" \
schematypens="http://www.w3.org/2001/XMLSchema"?>
<package format="3">
  <name>demo_pkg</name>
  <version>0.0.0</version>
  <description>TODO: Package description</description>
  <maintainer email="ada@example.com">Ada</maintainer>
  <license>TODO: License declaration</license>

  <depend>rclpy</depend>
  <depend>std_msgs</depend>

  <test_depend>ament_copyright</test_depend>
  <test_depend>ament_flake8</test_depend>
  <test_depend>ament_pep257</test_depend>
  <test_depend>python3-pytest</test_depend>

  <export>
    <build_type>ament_python</build_type>
  </export>
</package>
"""

SETUP_PY = """\
from setuptools import find_packages, setup

package_name = 'demo_pkg'

setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ada',
    maintainer_email='ada@example.com',
    description='TODO: Package description',
    license='TODO: License declaration',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'talker = demo_pkg.talker:main'
        ],
    },
)
"""

SETUP_CFG = """\
[develop]
script_dir=$base/lib/demo_pkg
[install]
install_scripts=$base/lib/demo_pkg
"""

NODE = """\
def main():
    print('Hi from demo_pkg.')


if __name__ == '__main__':
    main()
"""


def test_cli_creates_the_ros2_pkg_create_files(tmp_path: Path) -> None:
    result = run_cli(*CREATE, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    pkg = tmp_path / 'demo_pkg'
    assert (pkg / 'package.xml').read_text() == PACKAGE_XML
    assert (pkg / 'setup.py').read_text() == SETUP_PY
    assert (pkg / 'setup.cfg').read_text() == SETUP_CFG
    assert (pkg / 'demo_pkg' / 'talker.py').read_text() == NODE
    assert (pkg / 'resource' / 'demo_pkg').read_text() == ''
    assert (pkg / 'demo_pkg' / '__init__.py').read_text() == ''
    tests = sorted(p.name for p in (pkg / 'test').iterdir())
    assert tests == ['test_copyright.py', 'test_flake8.py', 'test_pep257.py']
    flake8 = (pkg / 'test' / 'test_flake8.py').read_text()
    assert 'from ament_flake8.main import main_with_errors' in flake8
    assert '@pytest.mark.flake8\n@pytest.mark.linter\ndef test_flake8():' in flake8
    copyright_test = (pkg / 'test' / 'test_copyright.py').read_text()
    assert "@pytest.mark.skip(reason='No copyright header" in copyright_test
    assert not (pkg / 'LICENSE').exists()  # the license is a TODO
    compile((pkg / 'setup.py').read_text(), 'setup.py', 'exec')
    assert doctor(pkg).findings == []


def test_cli_prints_what_ros2_pkg_create_prints(tmp_path: Path) -> None:
    result = run_cli(*CREATE, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[:15] == [
        'going to create a new package',
        'package name: demo_pkg',
        f'destination directory: {tmp_path}',
        'package format: 3',
        'version: 0.0.0',
        'description: TODO: Package description',
        "maintainer: ['Ada <ada@example.com>']",
        "licenses: ['TODO: License declaration']",
        'build type: ament_python',
        "dependencies: ['rclpy', 'std_msgs']",
        'node_name: talker',
        'creating folder ./demo_pkg',
        'creating ./demo_pkg/package.xml',
        'creating source folder',
        'creating folder ./demo_pkg/demo_pkg',
    ]
    assert lines[15:25] == [
        'creating ./demo_pkg/setup.py',
        'creating ./demo_pkg/setup.cfg',
        'creating folder ./demo_pkg/resource',
        'creating ./demo_pkg/resource/demo_pkg',
        'creating ./demo_pkg/demo_pkg/__init__.py',
        'creating folder ./demo_pkg/test',
        'creating ./demo_pkg/test/test_copyright.py',
        'creating ./demo_pkg/test/test_flake8.py',
        'creating ./demo_pkg/test/test_pep257.py',
        'creating ./demo_pkg/demo_pkg/talker.py',
    ]
    assert lines[25:28] == [
        '',
        "[WARNING]: Unknown license 'TODO: License declaration'.  This has been set in the "
        'package.xml, but no LICENSE file has been created.',
        'It is recommended to use one of the ament license identifiers:',
    ]
    assert 'Apache-2.0' in lines[28:] and 'MIT' in lines[28:]


def test_minimal_package_without_node(tmp_path: Path) -> None:
    """Lab 1.3 Part 1: `ros2 pkg create --build-type ament_python my_robot_system`."""
    result = run_cli('pkg', 'create', '--build-type', 'ament_python', 'my_robot_system',
                     '--license', 'MIT', cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    pkg = tmp_path / 'my_robot_system'
    setup_py = (pkg / 'setup.py').read_text()
    assert "        'console_scripts': [\n        ],\n" in setup_py
    assert '<depend>' not in (pkg / 'package.xml').read_text()
    assert (pkg / 'LICENSE').read_text().startswith('Permission is hereby granted, free of charge')
    assert 'node_name' not in result.stdout
    assert '[WARNING]' not in result.stdout
    assert not (pkg / 'launch').exists() and not (pkg / 'config').exists()


def test_with_launch_and_config_installs_them(tmp_path: Path) -> None:
    pkg = create_package('lab_pkg', tmp_path, dependencies=['rclpy'], node_name='sensor_node',
                         maintainer_name='Ada', maintainer_email='ada@example.com',
                         with_launch=True, with_config=True)
    assert pkg == tmp_path / 'lab_pkg'
    setup_py = (pkg / 'setup.py').read_text()
    assert setup_py.startswith('from glob import glob\n\nfrom setuptools import')
    assert "('share/' + package_name + '/launch', glob('launch/*'))," in setup_py
    assert "('share/' + package_name + '/config', glob('config/*'))," in setup_py
    launch = ET.parse(pkg / 'launch' / 'lab_pkg.launch.xml').getroot()
    assert launch.tag == 'launch'
    node = launch.find('node')
    assert node is not None
    assert node.attrib == {'pkg': 'lab_pkg', 'exec': 'sensor_node', 'name': 'sensor_node',
                           'output': 'screen'}
    param = node.find('param')
    assert param is not None
    assert param.attrib['from'] == '$(find-pkg-share lab_pkg)/config/params.yaml'
    params = load_param_file(pkg / 'config' / 'params.yaml')  # nested: rcl accepts it
    assert params == {'/**': {'use_sim_time': False}}
    assert doctor(pkg).findings == []


def test_with_launch_only(tmp_path: Path) -> None:
    pkg = create_package('lone_pkg', tmp_path, node_name='talker', with_launch=True)
    setup_py = (pkg / 'setup.py').read_text()
    assert "glob('launch/*')" in setup_py and "glob('config/*')" not in setup_py
    node = ET.parse(pkg / 'launch' / 'lone_pkg.launch.xml').getroot().find('node')
    assert node is not None and node.find('param') is None
    assert doctor(pkg).findings == []


def test_refuses_an_existing_directory(tmp_path: Path) -> None:
    (tmp_path / 'demo_pkg').mkdir()
    result = run_cli(*CREATE, cwd=tmp_path)
    assert result.returncode == 1
    assert 'Aborted! The directory already exists: ./demo_pkg' in result.stderr
    assert 'choose a different destination directory or package name' in result.stderr
    assert list((tmp_path / 'demo_pkg').iterdir()) == []
    assert 'going to create' not in result.stdout


@pytest.mark.parametrize('name', ['Demo', 'demo-pkg', '1demo', 'demo__pkg', 'd', 'my pkg',
                                  '_demo', 'demo_'])
def test_refuses_names_against_rep_144(tmp_path: Path, name: str) -> None:
    result = run_cli('pkg', 'create', '--build-type', 'ament_python', name, cwd=tmp_path)
    assert result.returncode == 1
    assert f"invalid package name '{name}': REP 144" in result.stderr
    assert 'fix: use a name like' in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_refuses_test_keyword_and_bad_node_names(tmp_path: Path) -> None:
    with pytest.raises(PackageError, match="can't be named 'test'"):
        create_package('test', tmp_path)
    with pytest.raises(PackageError, match='Python keyword'):
        create_package('import', tmp_path)
    with pytest.raises(PackageError, match="invalid node name 'my-node'"):
        create_package('fine_pkg', tmp_path, node_name='my-node')
    assert list(tmp_path.iterdir()) == []


def test_destination_directory(tmp_path: Path) -> None:
    result = run_cli('pkg', 'create', '--build-type', 'ament_python', 'far_pkg',
                     '--destination-directory', 'ws/src', cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert f'destination directory: {tmp_path / "ws" / "src"}' in result.stdout
    assert 'creating folder ws/src/far_pkg' in result.stdout
    assert (tmp_path / 'ws' / 'src' / 'far_pkg' / 'package.xml').is_file()


def test_pkg_list_prefix_executables_over_the_index() -> None:
    listing = run_cli('pkg', 'list')
    assert listing.returncode == 0
    names = listing.stdout.splitlines()
    assert names == sorted(names)
    assert {'robot_lab', 'rclpy', 'std_msgs'} <= set(names)

    prefix = run_cli('pkg', 'prefix', 'robot_lab')
    assert prefix.returncode == 0
    kit = Path(prefix.stdout.strip())
    assert (kit / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'robot_lab').is_file()
    share = run_cli('pkg', 'prefix', '--share', 'robot_lab')
    assert Path(share.stdout.strip()) == kit / 'share' / 'robot_lab'

    exes = run_cli('pkg', 'executables', 'robot_lab')
    assert exes.returncode == 0
    assert exes.stdout.splitlines() == [
        'robot_lab controller_node', 'robot_lab fibonacci_node', 'robot_lab robot_node',
        'robot_lab sensor_node', 'robot_lab switch_node',
    ]
    full = run_cli('pkg', 'executables', 'robot_lab', '--full-path')
    paths = [Path(p) for p in full.stdout.splitlines()]
    assert all(os.access(p, os.X_OK) and p.parent == kit / 'lib' / 'robot_lab' for p in paths)
    everything = run_cli('pkg', 'executables')
    assert 'robot_lab sensor_node' in everything.stdout.splitlines()


def test_pkg_prefix_and_executables_of_a_missing_package() -> None:
    prefix = run_cli('pkg', 'prefix', 'no_such_pkg')
    assert prefix.returncode == 1
    assert prefix.stderr.strip() == 'Package not found'
    exes = run_cli('pkg', 'executables', 'no_such_pkg')
    assert exes.returncode == 1
    assert exes.stderr.strip() == "Package 'no_such_pkg' not found"
