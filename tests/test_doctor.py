"""robot-lab doctor: every package rule fails on a package that breaks it and passes on
one that does not; the seed's Lab 1.3 package is caught; the environment checklist."""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from conftest import run_cli

from robot_lab.pkg.doctor import Report, doctor

DATA = Path(__file__).resolve().parent / 'data'
GOOD = DATA / 'pkg' / 'good_pkg'
LAB13 = DATA / 'seeds' / 'lab13' / 'my_robot_system'


@pytest.fixture
def pkg(tmp_path: Path) -> Path:
    """A fresh copy of the package every rule accepts."""
    return Path(shutil.copytree(GOOD, tmp_path / 'good_pkg'))


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f'{old!r} not in {path}'
    path.write_text(text.replace(old, new, 1))


def _line(path: Path, needle: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if needle in line)


def test_good_package_passes_every_rule(pkg: Path) -> None:
    report = doctor(pkg)
    assert report.findings == []
    assert report.ok
    result = run_cli('doctor', str(pkg))
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'no problems found' in result.stdout


MARKER_ENTRY = "            ['resource/' + package_name]),\n"
XML_ENTRY = "        ('share/' + package_name, ['package.xml']),\n"
LAUNCH_ENTRY = "        ('share/' + package_name + '/launch', glob('launch/*')),\n"
CONFIG_ENTRY = "        ('share/' + package_name + '/config', glob('config/*')),\n"

# (rule, severity, breakage, file the finding names, text on the line it names or None)
Breakage = Callable[[Path], None]
CASES: list[tuple[str, str, str, Breakage, str, str | None]] = [
    ('package.xml', 'error', 'not well-formed',
     lambda p: _edit(p / 'package.xml', '</version>', '</versio>'), 'package.xml', '</versio>'),
    ('package.xml-format', 'warning', 'format 2',
     lambda p: _edit(p / 'package.xml', 'format="3"', 'format="2"'), 'package.xml',
     'format="2"'),
    ('package.xml-name', 'error', 'name differs from folder',
     lambda p: _edit(p / 'package.xml', '<name>good_pkg', '<name>other_pkg'), 'package.xml',
     '<name>'),
    ('package.xml-build-type', 'error', 'no build_type',
     lambda p: _edit(p / 'package.xml',
                     '  <export>\n    <build_type>ament_python</build_type>\n  </export>\n', ''),
     'package.xml', '</package>'),
    ('package.xml-build-type', 'error', 'ament_cmake build_type',
     lambda p: _edit(p / 'package.xml', '>ament_python</build_type>', '>ament_cmake</build_type>'),
     'package.xml', '<build_type>'),
    ('package.xml-deps', 'warning', 'ament_cmake buildtool',
     lambda p: _edit(p / 'package.xml', '<buildtool_depend>ament_python',
                     '<buildtool_depend>ament_cmake'), 'package.xml', 'ament_cmake'),
    ('package.xml-valid', 'error', 'redundant depend and exec_depend',
     lambda p: _edit(p / 'package.xml', '<exec_depend>ros2launch',
                     '<exec_depend>std_msgs</exec_depend>\n  <exec_depend>ros2launch'),
     'package.xml', 'std_msgs'),
    ('setup.py', 'error', 'syntax error',
     lambda p: _edit(p / 'setup.py', "version='0.0.1',", "version='0.0.1'"), 'setup.py', None),
    ('setup.py-name', 'error', 'package_name differs',
     lambda p: _edit(p / 'setup.py', "package_name = 'good_pkg'", "package_name = 'good'"),
     'setup.py', 'name=package_name'),
    ('setup.py-data-files', 'error', 'marker not installed',
     lambda p: _edit(p / 'setup.py', MARKER_ENTRY, '            []),\n'),
     'setup.py', 'data_files='),
    ('setup.py-data-files', 'error', 'package.xml not installed',
     lambda p: _edit(p / 'setup.py', XML_ENTRY, ''),
     'setup.py', 'data_files='),
    ('setup.py-data-files', 'error', 'launch/ not installed (Lab 1.3 Part 6)',
     lambda p: _edit(p / 'setup.py', LAUNCH_ENTRY, ''),
     'setup.py', 'data_files='),
    ('setup.py-data-files', 'error', 'config/ not installed (Lab 1.3 Part 6)',
     lambda p: _edit(p / 'setup.py', CONFIG_ENTRY, ''),
     'setup.py', 'data_files='),
    ('setup.py-console-scripts', 'error', 'script module missing',
     lambda p: _edit(p / 'setup.py', 'good_pkg.talker:main', 'good_pkg.talk:main'), 'setup.py',
     'good_pkg.talk:main'),
    ('setup.py-console-scripts', 'error', 'script function missing',
     lambda p: _edit(p / 'setup.py', 'good_pkg.talker:main', 'good_pkg.talker:run'), 'setup.py',
     'good_pkg.talker:run'),
    ('setup.cfg', 'error', 'install_scripts wrong',
     lambda p: _edit(p / 'setup.cfg', 'install_scripts=$base/lib/good_pkg',
                     'install_scripts=$base/bin'), 'setup.cfg', 'install_scripts'),
    ('setup.cfg', 'error', 'setup.cfg missing',
     lambda p: (p / 'setup.cfg').unlink(), 'setup.cfg', None),
    ('resource', 'error', 'marker missing',
     lambda p: (p / 'resource' / 'good_pkg').unlink(), 'resource/good_pkg', None),
    ('resource', 'error', 'marker is a folder (the seed diagram)',
     lambda p: ((p / 'resource' / 'good_pkg').unlink(), (p / 'resource' / 'good_pkg').mkdir()),
     'resource/good_pkg', None),
    ('python-package', 'error', '__init__.py missing',
     lambda p: (p / 'good_pkg' / '__init__.py').unlink(), 'good_pkg/__init__.py', None),
    ('dependencies', 'error', 'imported message package not declared',
     lambda p: _edit(p / 'good_pkg' / 'talker.py', 'from std_msgs.msg import String\n',
                     'from std_msgs.msg import String\nfrom geometry_msgs.msg import Twist\n'),
     'good_pkg/talker.py', 'geometry_msgs'),
    ('param-file', 'error', 'flat parameter file (the seed)',
     lambda p: (p / 'config' / 'params.yaml').write_text('# flat\ngreeting: hello\n'),
     'config/params.yaml', 'greeting'),
]


@pytest.mark.parametrize(('rule', 'severity', 'what', 'breakage', 'file', 'needle'),
                         CASES, ids=[f'{c[0]}: {c[2]}' for c in CASES])
def test_rule_fails_on_broken_package(
    pkg: Path, rule: str, severity: str, what: str, breakage: Breakage, file: str,
    needle: str | None,
) -> None:
    breakage(pkg)
    report: Report = doctor(pkg)
    hits = [f for f in report.findings if f.rule == rule]
    assert hits, f'{what}: no {rule} finding in:\n{report}'
    finding = hits[0]
    assert finding.severity == severity
    assert finding.file is not None and finding.file.endswith(file), finding
    assert finding.fix, finding
    if needle is not None:
        assert finding.line == _line(pkg / file, needle), finding
    assert report.ok is (severity != 'error')
    # The other rules still pass: one breakage, one kind of finding (package.xml name
    # changes also make setup.py's name disagree, which is the same mistake seen twice).
    others = {f.rule for f in report.findings} - {rule, 'setup.py-name'}
    assert not others, str(report)


def test_folder_named_otherwise_is_only_a_warning(tmp_path: Path) -> None:
    """A checkout folder (e.g. main/) holding a consistent package: colcon accepts it."""
    pkg = Path(shutil.copytree(GOOD, tmp_path / 'checkout'))
    report = doctor(pkg)
    assert [(f.rule, f.severity) for f in report.findings] == [('package.xml-name', 'warning')]
    assert "package 'good_pkg' lives in folder 'checkout'" in report.findings[0].message
    assert report.ok


def test_relative_path(pkg: Path) -> None:
    result = run_cli('doctor', '.', cwd=pkg)
    assert result.returncode == 0, result.stdout
    assert 'no problems found' in result.stdout


def test_cli_prints_file_line_severity_and_fix(pkg: Path) -> None:
    _edit(pkg / 'setup.py', 'good_pkg.talker:main', 'good_pkg.talker:run')
    result = run_cli('doctor', str(pkg))
    assert result.returncode == 1
    line = _line(pkg / 'setup.py', 'good_pkg.talker:run')
    assert re.search(
        rf'^{re.escape(str(pkg / "setup.py"))}:{line}: error: console script .talker. calls '
        r'good_pkg\.talker:run, .* \(fix: .*\)$', result.stdout, re.MULTILINE,
    ), result.stdout


def test_warnings_alone_exit_zero(pkg: Path) -> None:
    _edit(pkg / 'package.xml', 'format="3"', 'format="2"')
    result = run_cli('doctor', str(pkg))
    assert result.returncode == 0, result.stdout
    assert ': warning: package format is 2' in result.stdout


def test_seed_lab13_package_as_written() -> None:
    """The acceptance case: missing <build_type> and the flat robot_params.yaml."""
    result = run_cli('doctor', str(LAB13))
    assert result.returncode != 0
    xml_line = _line(LAB13 / 'package.xml', '</package>')
    assert f'{LAB13 / "package.xml"}:{xml_line}: error: no <export><build_type>' in result.stdout
    params = LAB13 / 'config' / 'robot_params.yaml'
    first_value = _line(params, 'sensor_rate')
    assert (f'{params}:{first_value}: error: Cannot have a value before ros__parameters'
            in result.stdout), result.stdout
    assert 'ros__parameters' in result.stdout.split('robot_params.yaml')[-1]  # the nested form
    report = doctor(LAB13)
    assert {f.rule for f in report.errors} == {'package.xml-build-type', 'param-file'}


def test_fixed_seed_passes(tmp_path: Path) -> None:
    from seeds import copy_seed

    fixed = copy_seed(LAB13, tmp_path)
    assert doctor(fixed).findings == []


def test_not_a_folder(tmp_path: Path) -> None:
    result = run_cli('doctor', str(tmp_path / 'nope'))
    assert result.returncode == 1
    assert 'is not a folder' in result.stderr


def test_environment_checklist() -> None:
    report = doctor()
    names = [c.name for c in report.checks]
    for expected in ('Python', 'rclpy', 'RMW implementation', 'ROS_DOMAIN_ID',
                     'ROS_AUTOMATIC_DISCOVERY_RANGE', 'colcon', "kit package 'robot_lab'"):
        assert expected in names
    assert report.ok, str(report)
    result = run_cli('doctor')
    assert result.returncode == 0, result.stdout + result.stderr
    assert '[ok] RMW implementation: rmw_fastrtps_cpp' in result.stdout
    assert '[ok] ROS_AUTOMATIC_DISCOVERY_RANGE: LOCALHOST' in result.stdout
    assert re.search(r'\[ok\] colcon: colcon-core \d+\.\d+', result.stdout)


def test_environment_flags_bad_settings() -> None:
    bad = {'ROS_DOMAIN_ID': '300', 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET'}
    result = run_cli('doctor', env=bad)
    assert result.returncode == 1
    assert '[!!] ROS_DOMAIN_ID: 300' in result.stdout
    assert '[??] ROS_AUTOMATIC_DISCOVERY_RANGE: SUBNET' in result.stdout
