"""The ament prefix path: the user's AMENT_PREFIX_PATH, then the kit's prefix, then the venv.

Real ROS finds packages through `AMENT_PREFIX_PATH`. robot_lab adds two prefixes after the
user's: the kit's own (so `robot_lab` is found even from an editable install, which
installs no data_files) and the venv, which holds the message packages that came as
wheels. It lives below both `env` (which gives every child this path) and `pkg` (which
reads packages from it), so neither imports the other.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from pathlib import Path

__all__ = ['ament_prefixes', 'kit_prefix']

_MARKERS = Path('share', 'ament_index', 'resource_index', 'packages')
_KIT = 'robot_lab'
_NODES = ('sensor_node', 'controller_node', 'robot_node', 'switch_node', 'fibonacci_node')


def _source_root() -> Path | None:
    """The repository checkout robot_lab runs from, if it is one (editable install)."""
    root = Path(__file__).resolve().parents[1]
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
    # colcon warns about an AMENT_PREFIX_PATH entry without setup files (every `colcon build`
    # in a kernel would print it); this prefix needs none: robot_lab adds it itself.
    for name in ('local_setup.sh', 'local_setup.bash'):
        _write_if_changed(prefix / name, "# robot_lab's editable prefix: nothing to set up\n")
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
