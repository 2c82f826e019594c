"""The ament resource index: which packages exist, where their share/ and lib/ are.

Real ROS finds packages through `AMENT_PREFIX_PATH`; so does robot_lab. Two more
prefixes are searched after the user's: the kit's own (so `robot_lab` is found even
from an editable install, which installs no data_files) and the venv itself, which
holds the message packages that came as wheels.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from pathlib import Path

from robot_lab.errors import ExecutableNotFoundError, PackageNotFoundError

__all__ = [
    'ament_prefixes',
    'executables',
    'find_executable',
    'kit_prefix',
    'package_prefix',
    'package_share',
    'packages',
]

_MARKERS = Path('share', 'ament_index', 'resource_index', 'packages')
_KIT = 'robot_lab'
_NODES = ('sensor_node', 'controller_node', 'robot_node')


def _source_root() -> Path | None:
    """The repository checkout robot_lab runs from, if it is one (editable install)."""
    root = Path(__file__).resolve().parents[2]
    return root if (root / 'package.xml').is_file() and (root / 'launch').is_dir() else None


def _writable_prefix_home() -> Path:
    candidate = Path(sys.prefix) / 'var' / 'robot_lab' / 'prefix'
    try:
        candidate.mkdir(parents=True, exist_ok=True)
        if os.access(candidate, os.W_OK):
            return candidate
    except OSError:
        pass
    return Path.home() / '.cache' / 'robot_lab' / 'prefix'


def _write_if_changed(path: Path, text: str, mode: int = 0o644) -> None:
    if not path.is_file() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + f'.{os.getpid()}.tmp')
        tmp.write_text(text)
        tmp.chmod(mode)
        tmp.replace(path)


def kit_prefix() -> Path | None:
    """An ament prefix holding the kit's own `robot_lab` package.

    A regular `pip install .` already put it in sys.prefix. An editable install did not,
    so one is made (once, idempotently) whose share/robot_lab is the checkout itself:
    edits to launch/ and config/ take effect at the next launch.
    """
    if (Path(sys.prefix) / _MARKERS / _KIT).is_file():
        return Path(sys.prefix)
    root = _source_root()
    if root is None:
        return None
    prefix = _writable_prefix_home()
    _write_if_changed(prefix / _MARKERS / _KIT, '')
    share = prefix / 'share' / _KIT
    if not share.is_symlink() or share.resolve() != root:
        share.parent.mkdir(parents=True, exist_ok=True)
        tmp = share.with_name(f'.{_KIT}.{os.getpid()}')
        tmp.unlink(missing_ok=True)
        tmp.symlink_to(root, target_is_directory=True)
        tmp.replace(share)
    for node in _NODES:
        script = (
            f'#!{sys.executable}\n'
            f'"""Entry point of robot_lab\'s {node} (what colcon would install)."""\n'
            'import os\n'
            '# rclpy loads numpy; its OpenBLAS pool would spin a thread through start-up\n'
            '# in a node that does no linear algebra (~50 ms CPU per node).\n'
            "os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')\n"
            f'from robot_lab.nodes.{node} import main\n'
            "if __name__ == '__main__':\n"
            '    main()\n'
        )
        _write_if_changed(prefix / 'lib' / _KIT / node, script, 0o755)
    return prefix


def ament_prefixes(env: Mapping[str, str] | None = None) -> list[Path]:
    """AMENT_PREFIX_PATH entries first (a colcon build overrides the kit), then kit, venv."""
    env = os.environ if env is None else env
    found: list[Path] = []
    for entry in env.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if entry and Path(entry) not in found:
            found.append(Path(entry))
    for extra in (kit_prefix(), Path(sys.prefix)):
        if extra is not None and extra not in found and (extra / _MARKERS).is_dir():
            found.append(extra)
    return found


def packages(env: Mapping[str, str] | None = None) -> dict[str, Path]:
    """Every package in the index, mapped to the first prefix that has it."""
    result: dict[str, Path] = {}
    for prefix in ament_prefixes(env):
        markers = prefix / _MARKERS
        if markers.is_dir():
            for marker in sorted(markers.iterdir()):
                result.setdefault(marker.name, prefix)
    return result


def package_prefix(name: str, env: Mapping[str, str] | None = None) -> Path:
    """The install prefix of package `name`, as `ros2 pkg prefix` finds it."""
    prefixes = ament_prefixes(env)
    for prefix in prefixes:
        if (prefix / _MARKERS / name).is_file():
            return prefix
    searched = ', '.join(str(p) for p in prefixes) or '(none)'
    raise PackageNotFoundError(
        f"Package '{name}' not found (searched AMENT_PREFIX_PATH: {searched})",
        fix='build it with `robot-lab build` (or colcon build), then '
        '`source install/setup.bash` or robot_lab.use_workspace(...)',
    )


def package_share(name: str, env: Mapping[str, str] | None = None) -> Path:
    """`$(find-pkg-share name)`."""
    return package_prefix(name, env) / 'share' / name


def executables(name: str, env: Mapping[str, str] | None = None) -> list[str]:
    """The executables installed under <prefix>/lib/<name>, sorted."""
    libdir = package_prefix(name, env) / 'lib' / name
    if not libdir.is_dir():
        return []
    return sorted(
        p.name for p in libdir.iterdir() if p.is_file() and os.access(p, os.X_OK)
    )


def find_executable(package: str, executable: str, env: Mapping[str, str] | None = None) -> Path:
    """<prefix>/lib/<package>/<executable>, or an error listing what the package has."""
    libdir = package_prefix(package, env) / 'lib' / package
    path = libdir / executable
    if path.is_file() and os.access(path, os.X_OK):
        return path
    have = executables(package, env)
    listing = ', '.join(have) if have else 'none'
    raise ExecutableNotFoundError(
        f"executable '{executable}' not found on the libexec directory '{libdir}'",
        fix=f"package '{package}' has: {listing}",
    )
