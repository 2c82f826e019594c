"""Doctor rules on package.xml, the resource marker, imports and parameter files."""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator

from robot_lab.errors import RobotLabError
from robot_lab.pkg.doctor_findings import PackageUnderCheck, line_of
from robot_lab.pkg.doctor_setup import setup_py_name
from robot_lab.xml_lines import XmlElement, parse_xml_lines

__all__ = ['check_dependencies', 'check_package_xml', 'check_param_files', 'check_resource']

_INTERFACE_KINDS = ('msg', 'srv', 'action')
_BUILD_TYPE_XML = '<export><build_type>ament_python</build_type></export>'


def check_package_xml(pkg: PackageUnderCheck) -> None:
    path = pkg.dir / 'package.xml'
    file = pkg.rel('package.xml')
    if not path.is_file():
        pkg.add('package.xml', 'error', 'package.xml is missing: colcon will not see a package',
                file, fix='create it with robot-lab pkg create, or copy one and edit it')
        return
    text = path.read_text(errors='replace')
    try:
        root = parse_xml_lines(text, file, XmlElement, RobotLabError,
                               what='package.xml is not well-formed XML')
    except RobotLabError as err:
        pkg.add('package.xml', 'error', err.message, file, err.line, fix=err.fix)
        return
    pkg.xml = root
    if root.tag != 'package':
        pkg.add('package.xml', 'error', f'root tag is <{root.tag}>, expected <package>',
                file, root.line, fix='wrap the manifest in <package format="3">...</package>')
        return
    fmt = root.attrib.get('format', '1')
    if fmt != '3':
        pkg.add('package.xml-format', 'error' if fmt not in ('2',) else 'warning',
                f'package format is {fmt}, expected 3 (what ros2 pkg create writes)', file,
                root.line, fix='use <package format="3">')
    name_el = root.find('name')
    xml_name = name_el.text.strip() if name_el is not None else ''
    folder = pkg.name  # the folder's name until package.xml says otherwise
    if name_el is None or not xml_name:
        pkg.add('package.xml-name', 'error', 'package.xml has no <name>', file, root.line,
                fix=f'add <name>{folder}</name>')
    elif xml_name != folder and setup_py_name(pkg.dir) == xml_name:
        # package.xml and setup.py agree: colcon is happy, only the convention is broken.
        pkg.name = xml_name
        pkg.add('package.xml-name', 'warning',
                f"package '{xml_name}' lives in folder '{folder}' (ros2 pkg create names the "
                'folder after the package)', file, name_el.line,
                fix=f'rename the folder to {xml_name} if you can')
    elif xml_name != folder:
        # setup.py (or nothing) follows the folder: package.xml is the odd one out, and the
        # other rules keep the folder's name so one mistake gives one finding.
        pkg.add('package.xml-name', 'error',
                f"package name '{xml_name}' does not match its folder '{folder}'",
                file, name_el.line,
                fix=f'rename the folder to {xml_name} or set <name>{folder}</name>')
    for tag in ('depend', 'exec_depend'):
        pkg.declared |= {e.text.strip() for e in root.findall(tag)}
    export = root.find('export')
    build_type = export.find('build_type') if export is not None else None
    if build_type is None:
        pkg.add('package.xml-build-type', 'error',
                'no <export><build_type>: colcon treats the package as CMake '
                '(ament_cmake/catkin) and the build fails', file,
                export.line if export is not None else root.end_line,
                fix=f'add {_BUILD_TYPE_XML} before </package>')
    elif build_type.text.strip() != 'ament_python':
        pkg.add('package.xml-build-type', 'error',
                f"build type is '{build_type.text.strip()}', but this is a Python package",
                file, build_type.line, fix='use <build_type>ament_python</build_type>')
    for dep in root.findall('buildtool_depend'):
        if dep.text.strip().startswith(('ament_cmake', 'catkin')):
            pkg.add('package.xml-deps', 'warning',
                    f'<buildtool_depend>{dep.text.strip()}</buildtool_depend> in an ament_python '
                    'package', file, dep.line,
                    fix='remove it (ament_python packages need no CMake buildtool)')
    _catkin_validation(pkg, text, file)


def _catkin_validation(pkg: PackageUnderCheck, text: str, file: str) -> None:
    """What catkin_pkg (colcon's parser) refuses: redundant or missing tags, bad versions."""
    try:
        from catkin_pkg.package import (  # type: ignore[import-untyped]
            InvalidPackage,
            parse_package_string,
        )
    except ImportError:  # colcon-ros not installed: the rules above still ran
        return
    try:
        parse_package_string(text, filename=file)
    except InvalidPackage as err:
        for message in str(err.msg).splitlines():
            message = message.lstrip('- ').strip()
            if not message or message.endswith(':') or 'naming conventions' in message:
                continue
            quoted = re.findall(r"['\"]([^'\"]+)['\"]", message)
            line = next((n for q in quoted if (n := line_of(text, q)) is not None), None)
            pkg.add('package.xml-valid', 'error', message, file, line,
                    fix='colcon cannot parse the package until this is fixed')


def check_resource(pkg: PackageUnderCheck) -> None:
    path = pkg.dir / 'resource' / pkg.name
    file = pkg.rel('resource', pkg.name)
    if path.is_dir():
        pkg.add('resource', 'error', f'resource/{pkg.name} is a folder; the ament marker must '
                'be an (empty) file', file, fix=f'rmdir it and touch resource/{pkg.name}')
    elif not path.is_file():
        pkg.add('resource', 'error', f'resource/{pkg.name} is missing (setup.py installs it as '
                'the ament index marker; colcon build fails without it)', file,
                fix=f'create an empty file: touch resource/{pkg.name}')
    init = pkg.dir / pkg.name / '__init__.py'
    if (pkg.dir / 'setup.py').is_file() and not init.is_file():
        pkg.add('python-package', 'error', f'{pkg.name}/__init__.py is missing: setuptools will '
                'not install the node modules', pkg.rel(pkg.name, '__init__.py'),
                fix=f'create an empty {pkg.name}/__init__.py')


# --- dependencies of the node files ----------------------------------------------------


def _ros_imports(tree: ast.Module) -> Iterator[tuple[str, int]]:
    """(ROS package, line) for rclpy and every msg/srv/action import."""
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            parts = node.module.split('.')
            interface = len(parts) > 1 and parts[1] in _INTERFACE_KINDS
            # `from std_msgs import msg` names the kind as the imported name instead.
            kind_imported = len(parts) == 1 and any(a.name in _INTERFACE_KINDS for a in node.names)
            if parts[0] == 'rclpy' or interface or kind_imported:
                yield parts[0], node.lineno
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split('.')
                if parts[0] == 'rclpy' or (len(parts) > 1 and parts[1] in _INTERFACE_KINDS):
                    yield parts[0], node.lineno


def check_dependencies(pkg: PackageUnderCheck) -> None:
    if pkg.xml is None:
        return
    source = pkg.dir / pkg.name
    if not source.is_dir():
        return
    reported: set[str] = set()
    for py in sorted(source.rglob('*.py')):
        try:
            tree = ast.parse(py.read_text(errors='replace'))
        except SyntaxError as err:
            pkg.add('python-syntax', 'error', f'{py.name} does not parse: {err.msg}', str(py),
                    err.lineno, fix='fix the Python syntax at that line')
            continue
        for dep, line in _ros_imports(tree):
            if dep in pkg.declared or dep == pkg.name or dep in reported:
                continue
            reported.add(dep)
            pkg.add('dependencies', 'error',
                    f'imports {dep} but package.xml does not declare it', str(py), line,
                    fix=f'add <depend>{dep}</depend> to package.xml (rosdep and colcon '
                    'order builds by it)')


# --- parameter files -------------------------------------------------------------------


def check_param_files(pkg: PackageUnderCheck) -> None:
    config = pkg.dir / 'config'
    if not config.is_dir():
        return
    from robot_lab.errors import ParamFileError
    from robot_lab.params import load_param_file

    for path in sorted([*config.glob('*.yaml'), *config.glob('*.yml')]):
        try:
            load_param_file(path)
        except ParamFileError as err:
            pkg.add('param-file', 'error', err.message, pkg.rel('config', path.name),
                    err.line, fix=err.fix)
