"""Doctor rules on setup.py and setup.cfg, read with `ast` (nothing is executed)."""

from __future__ import annotations

import ast
import contextlib
import os
import re
from glob import glob
from pathlib import Path
from typing import Any

from robot_lab.pkg.doctor_findings import PackageUnderCheck, line_of

__all__ = ['check_setup_cfg', 'check_setup_py', 'setup_py_name']

_MARKER_DEST = 'share/ament_index/resource_index/packages'


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


def setup_py_name(pkg_dir: Path) -> str | None:
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


def check_setup_py(pkg: PackageUnderCheck) -> None:
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
        line = name_kw.lineno if name_kw is not None else line_of(text, 'package_name')
        pkg.add('setup.py-name', 'error',
                f"setup.py names the package '{declared}', but the package is '{pkg.name}'",
                file, line, fix=f"set package_name = '{pkg.name}'")
        # Check the rest as it will be once the name is fixed: one cause, one finding.
        evaluate.names['package_name'] = pkg.name
    _check_data_files(pkg, file, keywords.get('data_files'), evaluate, call.lineno)
    _check_console_scripts(pkg, file, keywords.get('entry_points'))


def _check_data_files(pkg: PackageUnderCheck, file: str, kw: ast.keyword | None,
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


def _check_console_scripts(pkg: PackageUnderCheck, file: str, kw: ast.keyword | None) -> None:
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


def _check_entry_point(pkg: PackageUnderCheck, file: str, spec: str, line: int) -> None:
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


def check_setup_cfg(pkg: PackageUnderCheck) -> None:
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
