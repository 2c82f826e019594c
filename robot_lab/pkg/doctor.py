"""`robot-lab doctor`: check a package the way an instructor would, before colcon does.

Every finding names the file and line to change and how. Nothing is executed: setup.py
and the node files are read with `ast`, package.xml with expat (for line numbers) and
catkin_pkg (the parser colcon itself uses), parameter files with rcl's rules
(robot_lab.params). Without a package, the environment is checked instead.
"""

from __future__ import annotations

import ast
import contextlib
import html
import os
import platform
import re
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from glob import glob
from pathlib import Path
from typing import Any
from xml.parsers import expat

__all__ = ['Check', 'Finding', 'Report', 'doctor']

_MARKER_DEST = 'share/ament_index/resource_index/packages'
_INTERFACE_KINDS = ('msg', 'srv', 'action')
_BUILD_TYPE_XML = '<export><build_type>ament_python</build_type></export>'


@dataclass(frozen=True)
class Finding:
    """One problem in a package: where it is, what it is, and how to fix it."""

    severity: str  # 'error' or 'warning'
    message: str
    file: str | None = None
    line: int | None = None
    fix: str | None = None
    rule: str = ''

    def __str__(self) -> str:
        where = ''
        if self.file is not None:
            where = f'{self.file}:{self.line}: ' if self.line else f'{self.file}: '
        fix = f' (fix: {self.fix})' if self.fix else ''
        return f'{where}{self.severity}: {self.message}{fix}'


@dataclass(frozen=True)
class Check:
    """One line of the environment checklist."""

    name: str
    ok: bool
    detail: str
    fix: str | None = None
    severity: str = 'error'  # what a failed check counts as

    def __str__(self) -> str:
        mark = '[ok]' if self.ok else ('[!!]' if self.severity == 'error' else '[??]')
        fix = f' (fix: {self.fix})' if self.fix and not self.ok else ''
        return f'{mark} {self.name}: {self.detail}{fix}'


@dataclass
class Report:
    """Findings for a package (or the environment checklist); `.ok` when no errors."""

    path: Path | None
    findings: list[Finding] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)

    @property
    def errors(self) -> list[Finding]:
        return [f for f in self.findings if f.severity == 'error']

    @property
    def warnings(self) -> list[Finding]:
        return [f for f in self.findings if f.severity == 'warning']

    @property
    def ok(self) -> bool:
        failed = [c for c in self.checks if not c.ok and c.severity == 'error']
        return not self.errors and not failed

    def rules(self) -> set[str]:
        return {f.rule for f in self.findings}

    def summary(self) -> str:
        if self.path is None:
            bad = sum(1 for c in self.checks if not c.ok)
            return 'environment OK' if bad == 0 else f'{bad} check(s) need attention'
        if not self.findings:
            return f'{self.path}: no problems found'
        return f'{self.path}: {len(self.errors)} error(s), {len(self.warnings)} warning(s)'

    def __str__(self) -> str:
        lines = [str(c) for c in self.checks] + [str(f) for f in self.findings]
        return '\n'.join([*lines, self.summary()])

    def _repr_html_(self) -> str:
        colours = {'error': '#cf222e', 'warning': '#9a6700'}
        rows = []
        for check in self.checks:
            colour = '#1a7f37' if check.ok else colours[check.severity]
            rows.append(f'<li style="color:{colour}">{html.escape(str(check))}</li>')
        for finding in self.findings:
            colour = colours.get(finding.severity, '#000')
            rows.append(f'<li style="color:{colour}"><code>{html.escape(str(finding))}</code></li>')
        head = html.escape(self.summary())
        return f'<div><b>{head}</b><ul>{"".join(rows)}</ul></div>'


# --- package.xml -----------------------------------------------------------------------


@dataclass
class _Element:
    tag: str
    attrs: dict[str, str]
    line: int
    end_line: int = 0
    text: str = ''
    children: list[_Element] = field(default_factory=list)

    def find(self, tag: str) -> _Element | None:
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag: str) -> list[_Element]:
        return [c for c in self.children if c.tag == tag]


def _parse_xml(text: str) -> _Element:
    """A tiny element tree that remembers the line of each start and end tag."""
    parser = expat.ParserCreate()
    stack: list[_Element] = []
    root: list[_Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        element = _Element(tag, dict(attrs), parser.CurrentLineNumber)
        if stack:
            stack[-1].children.append(element)
        else:
            root.append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop().end_line = parser.CurrentLineNumber

    def data(chunk: str) -> None:
        if stack:
            stack[-1].text += chunk

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = data
    parser.Parse(text, True)
    return root[0]


@dataclass
class _Package:
    """What the rules share: the package folder and what package.xml declares."""

    dir: Path
    name: str
    xml: _Element | None = None
    declared: set[str] = field(default_factory=set)  # depend + exec_depend
    findings: list[Finding] = field(default_factory=list)

    def rel(self, *parts: str) -> str:
        return str(self.dir.joinpath(*parts))

    def add(self, rule: str, severity: str, message: str, file: str | None,
            line: int | None = None, fix: str | None = None) -> None:
        self.findings.append(Finding(severity, message, file, line, fix, rule))


def _line_of(text: str, needle: str) -> int | None:
    for number, line in enumerate(text.splitlines(), 1):
        if needle in line:
            return number
    return None


def _check_package_xml(pkg: _Package) -> None:
    path = pkg.dir / 'package.xml'
    file = pkg.rel('package.xml')
    if not path.is_file():
        pkg.add('package.xml', 'error', 'package.xml is missing: colcon will not see a package',
                file, fix='create it with robot-lab pkg create, or copy one and edit it')
        return
    text = path.read_text(errors='replace')
    try:
        root = _parse_xml(text)
    except expat.ExpatError as err:
        pkg.add('package.xml', 'error', f'package.xml is not well-formed XML: '
                f'{expat.ErrorString(err.code)}', file, err.lineno,
                fix='close every tag and quote every attribute')
        return
    pkg.xml = root
    if root.tag != 'package':
        pkg.add('package.xml', 'error', f'root tag is <{root.tag}>, expected <package>',
                file, root.line, fix='wrap the manifest in <package format="3">...</package>')
        return
    fmt = root.attrs.get('format', '1')
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
    elif xml_name != folder and _setup_py_name(pkg.dir) == xml_name:
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


def _catkin_validation(pkg: _Package, text: str, file: str) -> None:
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
            line = next((n for q in quoted if (n := _line_of(text, q)) is not None), None)
            pkg.add('package.xml-valid', 'error', message, file, line,
                    fix='colcon cannot parse the package until this is fixed')


# --- setup.py --------------------------------------------------------------------------


class _SetupEvaluator:
    """Evaluates the few expression forms setup.py files use, without running them."""

    def __init__(self, pkg_dir: Path, names: dict[str, Any]) -> None:
        self.pkg_dir = pkg_dir
        self.names = names

    def __call__(self, node: ast.AST) -> Any:
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            raise ValueError(node.id)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            return self(node.left) + self(node.right)
        if isinstance(node, ast.JoinedStr):
            parts = []
            for value in node.values:
                if isinstance(value, ast.FormattedValue):
                    parts.append(str(self(value.value)))
                else:
                    parts.append(str(self(value)))
            return ''.join(parts)
        if isinstance(node, ast.List | ast.Tuple):
            return [self(e) for e in node.elts]
        if isinstance(node, ast.Call):
            func = ast.unparse(node.func)
            args = [self(a) for a in node.args]
            if func in ('os.path.join', 'path.join', 'join'):
                return os.path.join(*args)
            if func in ('glob', 'glob.glob'):
                found = sorted(glob(str(self.pkg_dir / args[0]), recursive=True))
                return [os.path.relpath(f, self.pkg_dir) for f in found]
            if func in ('str', 'os.fspath'):
                return str(args[0])
        raise ValueError(ast.unparse(node))


def _setup_call(tree: ast.Module) -> ast.Call | None:
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and ast.unparse(node.func) in ('setup', 'setuptools.setup'):
            return node
    return None


def _module_names(tree: ast.Module, evaluate: _SetupEvaluator) -> None:
    for node in tree.body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 \
                and isinstance(node.targets[0], ast.Name):
            try:
                evaluate.names[node.targets[0].id] = evaluate(node.value)
            except (ValueError, TypeError):
                continue


def _setup_py_name(pkg_dir: Path) -> str | None:
    """The name setup.py gives the package (`package_name = ...`), if it can be read."""
    try:
        tree = ast.parse((pkg_dir / 'setup.py').read_text(errors='replace'))
    except (OSError, SyntaxError):
        return None
    evaluate = _SetupEvaluator(pkg_dir, {})
    _module_names(tree, evaluate)
    call = _setup_call(tree)
    name = evaluate.names.get('package_name')
    for kw in call.keywords if call is not None else []:
        if kw.arg == 'name':
            with contextlib.suppress(ValueError, TypeError):
                name = evaluate(kw.value)
    return name if isinstance(name, str) else None


def _check_setup_py(pkg: _Package) -> None:
    path = pkg.dir / 'setup.py'
    file = pkg.rel('setup.py')
    if not path.is_file():
        pkg.add('setup.py', 'error', 'setup.py is missing (an ament_python package needs it)',
                file, fix='create the package with robot-lab pkg create and copy your code in')
        return
    text = path.read_text(errors='replace')
    try:
        tree = ast.parse(text, filename=file)
    except SyntaxError as err:
        pkg.add('setup.py', 'error', f'setup.py does not parse: {err.msg}', file, err.lineno,
                fix='fix the Python syntax at that line')
        return
    evaluate = _SetupEvaluator(pkg.dir, {})
    _module_names(tree, evaluate)
    call = _setup_call(tree)
    if call is None:
        pkg.add('setup.py', 'error', 'setup.py never calls setup()', file,
                fix='call setuptools.setup(...) as ros2 pkg create writes it')
        return
    keywords = {k.arg: k for k in call.keywords if k.arg is not None}
    declared = evaluate.names.get('package_name')
    name_kw = keywords.get('name')
    if name_kw is not None:
        with contextlib.suppress(ValueError, TypeError):
            declared = evaluate(name_kw.value)
    if isinstance(declared, str) and declared != pkg.name:
        line = name_kw.lineno if name_kw is not None else _line_of(text, 'package_name')
        pkg.add('setup.py-name', 'error',
                f"setup.py names the package '{declared}', but the package is '{pkg.name}'",
                file, line, fix=f"set package_name = '{pkg.name}'")
        # Check the rest as it will be once the name is fixed: one cause, one finding.
        evaluate.names['package_name'] = pkg.name
    _check_data_files(pkg, file, keywords.get('data_files'), evaluate, call.lineno)
    _check_console_scripts(pkg, file, keywords.get('entry_points'))


def _check_data_files(pkg: _Package, file: str, kw: ast.keyword | None,
                      evaluate: _SetupEvaluator, call_line: int) -> None:
    name = pkg.name
    entries: list[tuple[str, list[str], int]] = []
    line = kw.lineno if kw is not None else call_line
    if kw is not None:
        if not isinstance(kw.value, ast.List | ast.Tuple):
            pkg.add('setup.py-data-files', 'warning', 'data_files is not a literal list; '
                    'robot_lab cannot check it', file, line)
            return
        for element in kw.value.elts:
            try:
                dest, sources = evaluate(element)
            except (ValueError, TypeError):
                pkg.add('setup.py-data-files', 'warning',
                        f'cannot read data_files entry {ast.unparse(element)}', file,
                        element.lineno)
                continue
            entries.append((os.path.normpath(str(dest)), [os.path.normpath(s) for s in sources],
                            element.lineno))
    share = f'share/{name}'

    def installed(source: str) -> str | None:
        for dest, sources, _ in entries:
            if source in sources:
                return dest
        return None

    if installed(f'resource/{name}') != _MARKER_DEST:
        pkg.add('setup.py-data-files', 'error',
                'data_files does not install the package marker resource/' + name +
                ' (without it the ament index, and so ros2 run/launch, cannot find the package)',
                file, line, fix="add ('share/ament_index/resource_index/packages', "
                "['resource/' + package_name]), to data_files")
    if installed('package.xml') != share:
        pkg.add('setup.py-data-files', 'error', 'data_files does not install package.xml',
                file, line, fix="add ('share/' + package_name, ['package.xml']), to data_files")
    for folder in ('launch', 'config'):
        files = sorted(
            os.path.relpath(p, pkg.dir) for p in (pkg.dir / folder).glob('*') if p.is_file()
        ) if (pkg.dir / folder).is_dir() else []
        missing = [f for f in files if installed(f) is None]
        if missing:
            pkg.add('setup.py-data-files', 'error',
                    f'{folder}/ is not installed: {", ".join(missing)} will not be in '
                    f'share/{name}/{folder} after colcon build', file, line,
                    fix=f"add ('share/' + package_name + '/{folder}', glob('{folder}/*')), to "
                    'data_files (and from glob import glob)')
        misplaced = sorted({d for f in files if (d := installed(f)) and d != f'{share}/{folder}'})
        for dest in misplaced:
            pkg.add('setup.py-data-files', 'warning',
                    f"{folder}/ files are installed to '{dest}', not '{share}/{folder}' where "
                    f'$(find-pkg-share {name})/{folder}/... looks', file, line,
                    fix=f"install them with ('share/' + package_name + '/{folder}', "
                    f"glob('{folder}/*'))")


def _check_console_scripts(pkg: _Package, file: str, kw: ast.keyword | None) -> None:
    if kw is None or not isinstance(kw.value, ast.Dict):
        return
    for key, value in zip(kw.value.keys, kw.value.values, strict=True):
        if not (isinstance(key, ast.Constant) and key.value == 'console_scripts'):
            continue
        if not isinstance(value, ast.List | ast.Tuple):
            continue
        for item in value.elts:
            if isinstance(item, ast.Constant) and isinstance(item.value, str):
                _check_entry_point(pkg, file, item.value, item.lineno)


def _check_entry_point(pkg: _Package, file: str, spec: str, line: int) -> None:
    m = re.match(r'^\s*([^=\s]+)\s*=\s*([\w.]+)\s*:\s*([\w.]+)\s*$', spec)
    if m is None:
        pkg.add('setup.py-console-scripts', 'error',
                f"console script '{spec}' is not 'name = package.module:function'", file, line,
                fix=f"write it as 'my_node = {pkg.name}.my_node:main'")
        return
    exe, module, func = m.groups()
    base = pkg.dir.joinpath(*module.split('.'))
    module_file = base.with_suffix('.py') if base.with_suffix('.py').is_file() \
        else base / '__init__.py'
    if not module_file.is_file():
        pkg.add('setup.py-console-scripts', 'error',
                f"console script '{exe}' points at module {module}, but "
                f'{os.path.relpath(base, pkg.dir)}.py does not exist', file, line,
                fix=f'create {os.path.relpath(base, pkg.dir)}.py or correct the module path')
        return
    try:
        tree = ast.parse(module_file.read_text(errors='replace'))
    except SyntaxError as err:
        pkg.add('setup.py-console-scripts', 'error',
                f"console script '{exe}': {module_file.name} does not parse: {err.msg}",
                str(module_file), err.lineno, fix='fix the Python syntax at that line')
        return
    top = func.split('.')[0]
    defined: set[str] = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            defined.add(node.name)
        elif isinstance(node, ast.Assign):
            defined |= {t.id for t in node.targets if isinstance(t, ast.Name)}
        elif isinstance(node, ast.ImportFrom | ast.Import):
            defined |= {(a.asname or a.name).split('.')[0] for a in node.names}
    if top not in defined:
        pkg.add('setup.py-console-scripts', 'error',
                f"console script '{exe}' calls {module}:{func}, but "
                f'{os.path.relpath(module_file, pkg.dir)} defines no {top}()', file, line,
                fix=f'define def {top}(args=None): ... in {module_file.name}')


# --- setup.cfg, resource marker, Python package ----------------------------------------


def _check_setup_cfg(pkg: _Package) -> None:
    path = pkg.dir / 'setup.cfg'
    file = pkg.rel('setup.cfg')
    want = f'$base/lib/{pkg.name}'
    content = f'[develop]\\nscript_dir={want}\\n[install]\\ninstall_scripts={want}'
    if not path.is_file():
        pkg.add('setup.cfg', 'error', 'setup.cfg is missing: console scripts go to bin/, where '
                'ros2 run cannot find them', file, fix=f'create it with: {content}')
        return
    section = ''
    found: dict[str, tuple[str, int]] = {}
    for number, raw in enumerate(path.read_text(errors='replace').splitlines(), 1):
        line = raw.strip()
        if line.startswith('[') and line.endswith(']'):
            section = line[1:-1].strip()
        elif '=' in line and not line.startswith(('#', ';')):
            key, value = (s.strip() for s in line.split('=', 1))
            found[f'{section}.{key.replace("-", "_")}'] = (value, number)
    for key in ('develop.script_dir', 'install.install_scripts'):
        section, option = key.split('.')
        value, number = found.get(key, ('', 0))
        if value != want:
            problem = f"is '{value}'" if value else 'is missing'
            pkg.add('setup.cfg', 'error',
                    f'[{section}] {option} {problem}: executables must go to lib/{pkg.name} '
                    'for ros2 run and launch to find them', file, number or None,
                    fix=f'set {option}={want} under [{section}]')


def _check_resource(pkg: _Package) -> None:
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


def _check_dependencies(pkg: _Package) -> None:
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


def _check_param_files(pkg: _Package) -> None:
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


_RULES: tuple[Callable[[_Package], None], ...] = (
    _check_package_xml, _check_setup_py, _check_setup_cfg, _check_resource,
    _check_dependencies, _check_param_files,
)


def check_package(path: str | os.PathLike[str]) -> Report:
    """Every package rule, on the package folder `path` (the one holding package.xml)."""
    folder = Path(path)
    if not folder.is_dir():
        from robot_lab.errors import PackageError

        raise PackageError(f'{folder} is not a folder', fix='give the package folder '
                           '(the one holding package.xml)')
    pkg = _Package(folder, folder.resolve().name)
    for rule in _RULES:
        rule(pkg)
    return Report(folder, pkg.findings)


# --- environment -----------------------------------------------------------------------


def _environment_checks() -> list[Check]:
    from robot_lab.env import ros_environment

    env = ros_environment()
    checks: list[Check] = []
    version = sys.version_info
    checks.append(Check(
        'Python', version >= (3, 10) and sys.platform.startswith('linux'),
        f'{platform.python_version()} on {platform.system()} {platform.machine()}',
        fix='robot_lab needs Python >= 3.10 on Linux (the ROS 2 Jazzy wheels)',
    ))
    try:
        from importlib.metadata import PackageNotFoundError
        from importlib.metadata import version as dist_version

        import rclpy

        try:
            rclpy_version = dist_version('ros-jazzy-rclpy')
        except PackageNotFoundError:
            rclpy_version = 'unknown version'
        checks.append(Check('rclpy', True, f'imports ({rclpy_version}, {rclpy.__file__})'))
        from rclpy.utilities import get_rmw_implementation_identifier

        rmw = get_rmw_implementation_identifier()
        checks.append(Check('RMW implementation', True, rmw))
    except Exception as err:
        checks.append(Check('rclpy', False, f'cannot import rclpy: {err}',
                            fix="pip install 'robot_lab[kit]' in this venv"))
    domain = env.get('ROS_DOMAIN_ID', '')
    if not domain:
        checks.append(Check('ROS_DOMAIN_ID', True, 'unset (domain 0)'))
    else:
        good = domain.isdigit() and 0 <= int(domain) <= 232
        checks.append(Check(
            'ROS_DOMAIN_ID', good and int(domain) <= 101, domain,
            fix='use a number from 0 to 101 (safe on Linux)',
            severity='error' if not good else 'warning',
        ))
    discovery = env.get('ROS_AUTOMATIC_DISCOVERY_RANGE', '')
    checks.append(Check(
        'ROS_AUTOMATIC_DISCOVERY_RANGE', discovery == 'LOCALHOST', discovery or 'unset',
        fix='export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (keeps DDS on this machine)',
        severity='warning',
    ))
    if 'ROS_LOCALHOST_ONLY' in env:
        checks.append(Check('ROS_LOCALHOST_ONLY', False, 'set (deprecated in Jazzy)',
                            fix='unset it; ROS_AUTOMATIC_DISCOVERY_RANGE replaces it',
                            severity='warning'))
    colcon = Path(sys.prefix) / 'bin' / 'colcon'
    try:
        from importlib.metadata import version as dist_version

        colcon_version = dist_version('colcon-core')
    except Exception:
        colcon_version = ''
    checks.append(Check(
        'colcon', colcon.is_file() and bool(colcon_version),
        f'colcon-core {colcon_version} ({colcon})' if colcon_version else 'not installed',
        fix="pip install 'robot_lab[kit]' (colcon-core, colcon-ros, colcon-bash)",
    ))
    from robot_lab.errors import PackageNotFoundError as MissingPackage
    from robot_lab.pkg.index import package_share

    try:
        share = package_share('robot_lab', env)
        checks.append(Check("kit package 'robot_lab'", True, f'found ({share})'))
    except MissingPackage:
        checks.append(Check("kit package 'robot_lab'", False, 'not in the ament index',
                            fix='reinstall the kit: pip install -e .'))
    return checks


def doctor(path: str | os.PathLike[str] | None = None) -> Report:
    """Check a package folder (findings with file:line and fix) or, without one, the
    environment (a checklist)."""
    if path is None:
        return Report(None, checks=_environment_checks())
    return check_package(path)
