"""Workspaces: what `source install/setup.bash` does, done inside a Python process.

colcon writes, for every installed package, a `share/<pkg>/package.dsv` listing the
environment changes its setup scripts make (prepend the prefix to AMENT_PREFIX_PATH,
its site-packages to PYTHONPATH, ...). `use_workspace` applies those same files to
os.environ and sys.path, in colcon's order, so `robot-lab run/launch` children and the
in-kernel `robot_lab.launch(...)` find the packages. After a rebuild it is applied again
(build() does that), so the next launch runs the new code without a kernel restart.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import MutableMapping
from pathlib import Path

from robot_lab.errors import PackageError

__all__ = [
    'install_prefixes',
    'refresh_workspace',
    'use_workspace',
    'used_workspaces',
    'workspace_dir',
]

_PACKAGE_MARKERS = Path('share', 'colcon-core', 'packages')
_AMENT_MARKERS = Path('share', 'ament_index', 'resource_index', 'packages')
_used: list[Path] = []


def _install_dir(path: Path) -> Path:
    if (path / 'install').is_dir():
        return path / 'install'
    if (path / '.colcon_install_layout').is_file() or (path / 'setup.bash').is_file():
        return path
    raise PackageError(
        f'no install/ folder in {path}: the workspace has not been built',
        fix=f'build it first: robot-lab build {path}',
    )


def _packages(install: Path) -> dict[str, Path]:
    """Installed package name -> its prefix (isolated: install/<pkg>; merged: install)."""
    layout = install / '.colcon_install_layout'
    merged = layout.is_file() and layout.read_text().strip() == 'merged'
    found: dict[str, Path] = {}
    prefixes = [install] if merged else sorted(p for p in install.iterdir() if p.is_dir())
    for prefix in prefixes:
        for markers in (_PACKAGE_MARKERS, _AMENT_MARKERS):
            folder = prefix / markers
            if folder.is_dir():
                for marker in sorted(folder.iterdir()):
                    found.setdefault(marker.name, prefix)
    return found


def _topological(install: Path, packages: dict[str, Path]) -> list[str]:
    """Dependencies before the packages that need them, as colcon's setup scripts order."""
    deps: dict[str, set[str]] = {}
    for name, prefix in packages.items():
        marker = prefix / _PACKAGE_MARKERS / name
        text = marker.read_text().strip() if marker.is_file() else ''
        deps[name] = {d for d in text.split(os.pathsep) if d in packages and d != name}
    order: list[str] = []
    while deps:
        ready = sorted(name for name, needs in deps.items() if not needs - set(order))
        if not ready:  # a cycle: take the rest alphabetically
            ready = sorted(deps)
        for name in ready:
            order.append(name)
            del deps[name]
    return order


def install_prefixes(path: str | os.PathLike[str] = '.') -> list[Path]:
    """The install prefixes of a built workspace, dependencies first."""
    install = _install_dir(Path(path).expanduser().resolve())
    packages = _packages(install)
    ordered: list[Path] = []
    for name in _topological(install, packages):
        if packages[name] not in ordered:
            ordered.append(packages[name])
    return ordered


def _prepend(env: MutableMapping[str, str], name: str, value: str) -> None:
    parts = [p for p in env.get(name, '').split(os.pathsep) if p and p != value]
    env[name] = os.pathsep.join([value, *parts])


def _append(env: MutableMapping[str, str], name: str, value: str) -> None:
    parts = [p for p in env.get(name, '').split(os.pathsep) if p and p != value]
    env[name] = os.pathsep.join([*parts, value])


def _apply_dsv(dsv: Path, prefix: Path, env: MutableMapping[str, str], seen: set[Path]) -> None:
    """Apply one colcon .dsv file (the format behind package.sh/.bash) to `env`."""
    if dsv in seen or not dsv.is_file():
        return
    seen.add(dsv)
    for line in dsv.read_text().splitlines():
        if not line.strip() or line.startswith('#') or ';' not in line:
            continue
        kind, rest = line.split(';', 1)
        if kind == 'source':
            target = Path(rest) if os.path.isabs(rest) else prefix / rest
            _apply_dsv(target.with_suffix('.dsv'), prefix, env, seen)
            continue
        name, _, values = rest.partition(';')
        paths = [str(prefix / v) if v else str(prefix) for v in values.split(';')]
        for value in paths:
            if kind == 'set':
                env[name] = value
            elif kind == 'set-if-unset':
                env.setdefault(name, value)
            elif kind == 'prepend-non-duplicate':
                _prepend(env, name, value)
            elif kind == 'prepend-non-duplicate-if-exists':
                if Path(value).exists():
                    _prepend(env, name, value)
            elif kind == 'append-non-duplicate':
                _append(env, name, value)


def _forget_modules(roots: list[Path]) -> None:
    """Drop already-imported modules that came from this workspace, so a rebuild is seen."""
    importlib.invalidate_caches()
    for name, module in list(sys.modules.items()):
        file = getattr(module, '__file__', None)
        if not file:
            continue
        resolved = Path(file).resolve()
        if any(resolved.is_relative_to(root) for root in roots):
            del sys.modules[name]


def use_workspace(path: str | os.PathLike[str] = '.', *, libraries: bool = True) -> list[Path]:
    """In this process, what `source <ws>/install/setup.bash` does in a shell.

    Updates os.environ (AMENT_PREFIX_PATH, PYTHONPATH, ... for every child started later)
    and sys.path (for imports here). Call it again after a rebuild; `build()` does.
    Returns the prefixes, dependencies first. `libraries=False`: the workspace's shared
    libraries are not loaded here (a grader must not run a student's code in its process).
    """
    root = Path(path).expanduser().resolve()
    install = _install_dir(root)
    packages = _packages(install)
    if not packages:
        raise PackageError(
            f'{install} holds no installed packages',
            fix=f'build the workspace first: robot-lab build {install.parent}',
        )
    prefixes: list[Path] = []
    seen: set[Path] = set()
    for name in _topological(install, packages):
        prefix = packages[name]
        dsv = prefix / 'share' / name / 'package.dsv'
        if dsv.is_file():
            _apply_dsv(dsv, prefix, os.environ, seen)
        else:  # not built by colcon's shell extensions: the two variables that matter
            _prepend(os.environ, 'AMENT_PREFIX_PATH', str(prefix))
        if prefix not in prefixes:
            prefixes.append(prefix)
    # Children read PYTHONPATH; this process needs the same entries on sys.path
    # (under install/, or build/ for a --symlink-install).
    ws = install.parent if install.name == 'install' else install
    for entry in reversed(os.environ.get('PYTHONPATH', '').split(os.pathsep)):
        if entry and Path(entry).is_relative_to(ws):
            if entry in sys.path:
                sys.path.remove(entry)
            sys.path.insert(0, entry)
    _forget_modules([install, ws / 'build'])
    if libraries:
        _load_libraries(prefixes)
    if ws in _used:
        _used.remove(ws)
    _used.append(ws)
    return prefixes


def _load_libraries(prefixes: list[Path]) -> None:
    """Load the workspace's shared libraries (an interface package's type support) now.

    A shell's `source` puts <prefix>/lib on LD_LIBRARY_PATH before Python starts; a running
    kernel cannot change its own library path, but once a library is loaded by full path
    the dynamic loader resolves later imports' dependencies on it by name. Libraries are
    retried until no more load, as they depend on each other in no listed order.
    """
    from robot_lab.linux.libc import load_global

    pending = [lib for prefix in prefixes for lib in sorted((prefix / 'lib').glob('lib*.so'))]
    while pending:
        failed = []
        for lib in pending:
            try:
                load_global(lib)
            except OSError:
                failed.append(lib)
        if len(failed) == len(pending):
            return  # what is left needs something else: its import will say what
        pending = failed


def used_workspaces() -> list[Path]:
    """The workspaces `use_workspace` applied in this process, most recent last."""
    return list(_used)


def refresh_workspace(path: str | os.PathLike[str]) -> None:
    """Re-apply a workspace already in use (after a rebuild); a no-op otherwise."""
    root = Path(path).expanduser().resolve()
    if root in _used and (root / 'install').is_dir():
        use_workspace(root)


def _repository_root() -> Path | None:
    root = Path(__file__).resolve().parents[2]
    return root if (root / '.git').exists() or (root / 'setup.py').is_file() else None


def workspace_dir(create: bool = True) -> Path:
    """The scratch workspace for student work: $ROBOT_LAB_WORKSPACE or ~/robot_lab_ws.

    Never inside the kit's repository: colcon would find the kit's own package.xml there.
    """
    path = Path(os.environ.get('ROBOT_LAB_WORKSPACE', '~/robot_lab_ws')).expanduser().resolve()
    repo = _repository_root()
    if repo is not None and path.is_relative_to(repo):
        raise PackageError(
            f'workspace {path} is inside the robot_lab repository {repo}',
            fix='set ROBOT_LAB_WORKSPACE to a folder outside it (default ~/robot_lab_ws)',
        )
    if create:
        (path / 'src').mkdir(parents=True, exist_ok=True)
    return path
