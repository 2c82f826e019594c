"""Checks of the student's package: its files, answers, setup.py, launch file, build."""

from __future__ import annotations

import contextlib
import traceback
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from robot_lab.grading.check.base import CheckError, judged, passed, student_frames

__all__ = [
    'answered',
    'files_exist',
    'launch_file_nodes',
    'node_starts',
    'package_built',
    'readme_explains',
    'setup_py',
    'stop_node',
]


@judged
def files_exist(root: str | Path, paths: Iterable[str], hint: str | None = None) -> None:
    """Each of `paths` exists under `root` (a folder path ends with '/').

    `hint` says how the student makes them; by default, how a missing folder is made.
    """
    base = Path(root)
    wanted = list(paths)
    missing = []
    for rel in wanted:
        target = base / rel
        ok = target.is_dir() if rel.endswith('/') else target.is_file()
        if not ok:
            missing.append(rel)
    if missing:
        default = ('make the missing folders (`mkdir -p`) in your answer cell, run it, then '
                   'this check again' if any(m.endswith('/') for m in missing) else
                   'run the cell above that writes them, then this check again')
        raise CheckError(f'{", ".join(wanted)} in {base.name}/', f'missing {", ".join(missing)}',
                         hint or default)
    passed(f'{base.name}/ has {", ".join(wanted)}')


@judged
def package_built(workspace: str | Path, package: str,
                  executables: Iterable[str] = ()) -> None:
    """colcon installed `package` (ament index marker, package.xml, its executables)."""
    prefix = Path(workspace) / 'install' / package
    need = [Path('share/ament_index/resource_index/packages') / package,
            Path('share') / package / 'package.xml',
            *(Path('lib') / package / exe for exe in executables)]
    missing = [str(p) for p in need if not (prefix / p).exists()]
    if missing:
        only_executables = all(m.startswith('lib/') for m in missing)
        raise CheckError(f'{package} built and installed in install/{package}',
                         f'missing {", ".join(missing)}',
                         'a new console script needs a build: run the colcon build cell again '
                         '(and read its output)' if only_executables else
                         'read the build output above; fix the first error and build again')
    exes = list(executables)
    passed(f'{package} is installed' + (f' with {", ".join(exes)}' if exes else ''))


# What nbgrader's ClearSolutions leaves where an answer was (`robot-lab course release`).
_PLACEHOLDERS = ('YOUR CODE HERE', 'raise NotImplementedError')


@judged
def answered(path: str | Path, what: str,
             hint: str = 'replace the placeholder lines of your answer cell with your code, '
                         'then run that cell again') -> None:
    """`path` holds the student's `what`, not the placeholder a released copy starts with."""
    file = Path(path)
    if not file.is_file():
        raise CheckError(f'{what} in {file.name}', f'there is no {file.name} yet',
                         'run your answer cell above: it writes the file')
    for number, line in enumerate(file.read_text(errors='replace').splitlines(), 1):
        if any(mark in line for mark in _PLACEHOLDERS):
            raise CheckError(f'{what} in {file.name}',
                             f'line {number} still holds the placeholder `{line.strip()}`', hint)
    passed(f'{file.name} holds {what}')


class _InKernel:
    """A node node_starts spins in the kernel, owned by the check cell's run."""

    def __init__(self, node: Any) -> None:
        self.node = node

    def close(self) -> None:
        stop_node(self.node)

    def __repr__(self) -> str:
        return f'<node {self.node.get_name()} started by a check>'


def _destroy_half_built(err: BaseException) -> None:
    """A constructor that raised after `super().__init__` leaves a node with publishers in
    this kernel's context; destroy it, or its topics keep their (maybe wrong) types."""
    from rclpy.node import Node

    tb = err.__traceback__
    while tb is not None:
        candidate = tb.tb_frame.f_locals.get('self')
        if isinstance(candidate, Node):
            with contextlib.suppress(Exception):  # half-built indeed: nothing more to free
                candidate.destroy_node()
            return
        tb = tb.tb_next


@judged
def node_starts(module: str, cls: str, package: str = 'my_robot_system',
                hint: str = 'read the line named above in your answer cell, fix it, run the '
                            'cell and then this check again') -> Any:
    """The student's node class imports afresh, constructs, and spins in the kernel's session.

    The module is reloaded, so an edited and re-run `%%writefile` cell counts without a
    kernel restart. The node belongs to this run of the check cell: the cell's next run, or
    its failure, stops it (robot_lab.notebook_cell). Returns the node (`stop_node` stops it
    sooner).
    """
    import importlib
    import sys

    from robot_lab.notebook_cell import cell_owns
    from robot_lab.rclpy_session import session

    name = f'{package}.{module}'
    what = f'{cls}() from {module}.py to start'
    session()  # the context the node joins
    try:
        importlib.invalidate_caches()
        loaded = importlib.reload(sys.modules[name]) if name in sys.modules \
            else importlib.import_module(name)
        node = getattr(loaded, cls)()
    except Exception as err:
        _destroy_half_built(err)
        frames = traceback.extract_tb(err.__traceback__)
        where = next((f'{Path(f.filename).name} line {f.lineno}' for f in reversed(frames)
                      if f.filename.endswith(f'{module}.py')), name)
        if isinstance(err, SyntaxError) and err.filename:
            where = f'{Path(err.filename).name} line {err.lineno}'
            err = SyntaxError(err.msg)  # the place is said once, in `where`
        text = f'{type(err).__name__}' + (f': {err}' if str(err) else '')
        if isinstance(err, NotImplementedError):
            text += ' (the placeholder is still there)'
        elif isinstance(err, ModuleNotFoundError) and err.name in (package, name):
            text += f' (is {package} built, and this kernel told: robot_lab.use_workspace(ws))'
        elif hasattr(err, 'try_hint'):  # tf2's errors: a lookup while the node is built
            hint = ('nothing has arrived while your node is being built (it spins only '
                    'afterwards, so timeout= cannot help here): look the transform up where '
                    'data comes, in a callback or a timer, catching tf2_ros.TransformException')
        raise CheckError(what, f'{text} at {where}', hint, student_frames(
            err, lambda f: f.endswith(f'{module}.py'))) from None
    session().callback_errors.clear()  # what failed before belongs to nodes now gone
    session().add_node(node)
    cell_owns(_InKernel(node))
    passed(f'{cls} runs as node /{node.get_name()}')
    return node


def stop_node(node: Any) -> None:
    """Take a node `node_starts` returned out of the kernel's session and destroy it.

    Stopping a node that is stopped already does nothing.
    """
    from robot_lab.rclpy_session import session

    session().remove_node(node)
    node.destroy_node()


def _console_scripts(setup_py: Path) -> list[str]:
    import ast

    tree = ast.parse(setup_py.read_text(errors='replace'), filename=setup_py.name)
    found: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values, strict=True):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts' \
                        and isinstance(value, ast.List | ast.Tuple):
                    found += [' '.join(e.value.split()) for e in value.elts
                              if isinstance(e, ast.Constant) and isinstance(e.value, str)]
    return found


def _console_scripts_differ(missing: list[str], declared: list[str],
                            want: list[str]) -> tuple[str, str]:
    """What is wrong with the declared console scripts: a misspelt entry, or a missing one."""
    import difflib

    extra = [d for d in declared if d not in want]
    for wanted in missing:
        near = difflib.get_close_matches(wanted, extra, n=1, cutoff=0.6)
        if near:
            return (f'setup.py declares {near[0]!r}, not {wanted!r}',
                    'fix that string: it is `executable = package.module:function`, the module '
                    'named as its file (without .py) and the function `main`')
    if not declared:
        return ('setup.py declares no console_scripts',
                "add one 'name = package.module:main' string per node to "
                "entry_points={'console_scripts': [...]}")
    return (f'setup.py declares {", ".join(repr(d) for d in declared)}; '
            f'{", ".join(repr(m) for m in missing)} is missing',
            "add the missing 'name = package.module:main' string to "
            "entry_points={'console_scripts': [...]}")


@judged
def setup_py(pkg: str | Path, executables: Mapping[str, str],
             installs: Mapping[str, str] | None = None) -> None:
    """setup.py declares `executables` (name -> 'module:function') and installs `installs`.

    `installs` maps a folder to a file it will hold (e.g. 'launch': 'robot.launch.xml');
    the kit's package checker reads setup.py on a scratch copy that has those files, so
    data_files are checked before the files exist. Console scripts whose module is not
    written yet are not findings here (notebook 02 writes the modules).
    """
    import shutil
    import tempfile

    from robot_lab.pkg.doctor import check_package

    folder = Path(pkg)
    source = folder / 'setup.py'
    try:
        declared = _console_scripts(source)
    except (OSError, SyntaxError) as err:
        line = getattr(err, 'lineno', None)
        raise CheckError('a setup.py Python can read',
                         f'{type(err).__name__}: {err}' + (f' (line {line})' if line else ''),
                         'fix the line named; a placeholder left in a list is a syntax error'
                         ) from None
    want = [f'{name} = {target}' for name, target in executables.items()]
    missing = [w for w in want if w not in declared]
    if missing:
        raise CheckError(f'console_scripts {", ".join(repr(w) for w in want)}',
                         *_console_scripts_differ(missing, declared, want))
    with tempfile.TemporaryDirectory() as tmp:
        probe = Path(tmp) / folder.resolve().name
        probe.mkdir()
        for name in ('package.xml', 'setup.py', 'setup.cfg'):
            if (folder / name).is_file():
                shutil.copy(folder / name, probe / name)
        (probe / 'resource').mkdir()
        (probe / 'resource' / probe.name).touch()
        for sub, example in (installs or {}).items():
            (probe / sub).mkdir()
            (probe / sub / example).touch()
        problems = [f for f in check_package(probe).findings
                    if f.rule.startswith('setup.py') and f.rule != 'setup.py-console-scripts']
    if problems:
        raise CheckError('setup.py to install ' + ', '.join(
            f'{sub}/*' for sub in installs or {}), problems[0].message,
                         problems[0].fix or "compare data_files with the lab's setup.py")
    where = ', '.join(f'{sub}/' for sub in installs or {})
    passed('setup.py declares ' + ', '.join(executables)
           + (f' and installs {where}' if where else ''))


@judged
def launch_file_nodes(path: str | Path, nodes: Mapping[str, str]) -> None:
    """The XML launch file starts each node name with its executable and a parameter file."""
    import xml.etree.ElementTree as ElementTree

    file = Path(path)
    try:
        root = ElementTree.parse(file).getroot()
    except (OSError, ElementTree.ParseError) as err:
        raise CheckError(f'an XML launch file {file.name}', f'it cannot be read: {err}',
                         'write it with the answer cell above; every tag must be closed') \
            from None
    found = {el.get('name', ''): el for el in root.iter('node')}
    for name, exe in nodes.items():
        el = found.get(name)
        if el is None or el.get('exec') != exe:
            seen = ', '.join(f'{n or "(no name)"} runs {e.get("exec")}' for n, e in found.items())
            raise CheckError(f'<node exec="{exe}" name="{name}"> in {file.name}',
                             f'it has {seen or "no <node> elements"}',
                             'one <node pkg="…" exec="…" name="…"> per node: exec= is the '
                             'executable (console_scripts), name= the node name (the one your '
                             'parameter file uses)')
        if not any(p.get('from') for p in el.iter('param')):
            raise CheckError(f'node {name} to load the parameter file',
                             'it has no <param from="…"/>',
                             'add <param from="$(find-pkg-share PACKAGE)/config/FILE.yaml"/>')
    passed(f'{file.name} starts {", ".join(nodes)}, each with a parameter file')


@judged
def readme_explains(path: str | Path, commands: Iterable[str]) -> None:
    """The README exists and shows these commands (build, launch …)."""
    file = Path(path)
    text = file.read_text(errors='replace') if file.is_file() else ''
    missing = [c for c in commands if c not in text]
    if not text or missing:
        raise CheckError(f'{file.name} with the commands {", ".join(commands)}',
                         'there is no README' if not text else f'it lacks {", ".join(missing)}',
                         'write how to build and launch your package, commands in code blocks')
    passed(f'{file.name} shows {", ".join(commands)}')
