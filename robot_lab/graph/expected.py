"""What the graph should contain: the nodes that running launches have started.

DDS cannot say when discovery is complete, so a `node list` right after a launch either
waits a fixed window or risks a partial answer. The launcher knows better: it writes the
names of the node processes it has running to a small file per launch (in the graph's
runtime directory, one per ROS_DOMAIN_ID and discovery setting). A query that sees all of
those names can answer at once; names of processes that died no longer count, and files
of launchers that were killed are removed by the next reader.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path

from robot_lab.linux import procfs
from robot_lab.linux.procfs import process_running

__all__ = ['LaunchAnnouncement', 'announced_nodes', 'expected_nodes', 'graph_dir', 'graph_key']

# What decides whether two processes share a graph (and so a daemon and these files).
_GRAPH_VARIABLES = (
    'ROS_AUTOMATIC_DISCOVERY_RANGE',
    'ROS_STATIC_PEERS',
    'ROS_LOCALHOST_ONLY',
    'RMW_IMPLEMENTATION',
    'FASTRTPS_DEFAULT_PROFILES_FILE',
    'FASTDDS_DEFAULT_PROFILES_FILE',
)


def graph_key(env: Mapping[str, str] | None = None) -> str:
    """`d<domain>-<range>-<hash>`: equal for processes that see the same DDS graph."""
    from robot_lab.domain import domain_for

    source = os.environ if env is None else env
    # Unset ROS_DOMAIN_ID means the user's own domain (from the registry `source` names).
    domain = str(domain_for(source))
    return _key((domain, *(source.get(k) for k in _GRAPH_VARIABLES)), procfs.net_namespace())


@functools.lru_cache(maxsize=16)
def _key(values: tuple[str | None, ...], network: str) -> str:
    from robot_lab.env import apply_ros_defaults

    # The kit's defaults (discovery range, Fast DDS profile) apply to every process it
    # starts, so a shell without them and a node with them share one graph.
    resolved = {k: v for k, v in zip(('ROS_DOMAIN_ID', *_GRAPH_VARIABLES), values, strict=True)
                if v is not None}
    apply_ros_defaults(resolved)
    domain = resolved.get('ROS_DOMAIN_ID', '').strip() or '0'
    discovery = resolved.get('ROS_AUTOMATIC_DISCOVERY_RANGE', '').strip().lower() or 'default'
    # A graph is also its network namespace: one in another (a grading job, a second test
    # run) is not heard, so its daemon and launches are not this graph's.
    digest = hashlib.sha1(
        '\0'.join([*(resolved.get(k, '') for k in _GRAPH_VARIABLES), network]).encode()
    ).hexdigest()[:8]
    return f'd{domain}-{discovery}-{digest}'


def graph_dir(env: Mapping[str, str] | None = None, create: bool = False) -> Path:
    """The runtime directory of one graph: the daemon's socket and the launches' files.

    Under $XDG_RUNTIME_DIR when there is one, else a per-user directory in /tmp (mode 0700,
    so other users can neither read nor plant files).
    """
    runtime = os.environ.get('XDG_RUNTIME_DIR', '')
    if runtime and os.path.isdir(runtime):
        base = Path(runtime) / 'robot_lab'
    else:
        base = Path(tempfile.gettempdir()) / f'robot_lab-{os.getuid()}'
    path = base / 'graph' / graph_key(env)
    if create:
        path.mkdir(mode=0o700, parents=True, exist_ok=True)
        base.chmod(0o700)
    return path


class LaunchAnnouncement:
    """The launcher's side: keeps `launch-<pid>.json` equal to its running nodes."""

    def __init__(self, directory: Path) -> None:
        self.directory = directory
        self._path = directory / f'launch-{os.getpid()}.json'
        self._last: list[tuple[str, int]] | None = None

    def starting(self) -> None:
        """Announce a launch whose nodes are not known yet (its file is being read): a
        query that arrives now waits for the list instead of answering without them."""
        self._write(None)

    def update(self, nodes: Iterable[tuple[str, int]]) -> None:
        """Announce (full name, pid) of every node process that is running now."""
        current = sorted(nodes)
        if current != self._last:
            self._write(current)

    def _write(self, nodes: list[tuple[str, int]] | None) -> None:
        self._last = nodes
        with contextlib.suppress(OSError):  # a read-only /tmp only costs the hint
            self.directory.mkdir(mode=0o700, parents=True, exist_ok=True)
            listed = None if nodes is None else [{'name': n, 'pid': p} for n, p in nodes]
            text = json.dumps({'launcher': os.getpid(), 'nodes': listed})
            partial = self._path.with_suffix('.tmp')
            partial.write_text(text, encoding='utf-8')
            partial.replace(self._path)  # readers never see half a file

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self._path.unlink()


def _announcements(directory: Path) -> list[tuple[Path, int, list[tuple[str, int]] | None]]:
    """(file, launcher pid, [(name, pid)] or None while starting) of each launch file."""
    found: list[tuple[Path, int, list[tuple[str, int]] | None]] = []
    try:
        files = list(directory.glob('launch-*.json'))
    except OSError:
        return found
    for path in files:
        try:
            data = json.loads(path.read_text(encoding='utf-8'))
            launcher = int(data['launcher'])
            listed = data['nodes']
            nodes = None if listed is None else [(str(n['name']), int(n['pid'])) for n in listed]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        found.append((path, launcher, nodes))
    return found


def announced_nodes(directory: Path) -> list[tuple[str, int]]:
    """(full name, pid) of every node the launch files list, running or not: the graph
    daemon remembers them, so it can drop a node the moment its process is gone."""
    return [pair for _path, _launcher, nodes in _announcements(directory) for pair in nodes or ()]


def expected_nodes(directory: Path) -> set[str] | None:
    """Full names of the nodes that running launches of this graph have up right now.

    `directory` is the graph's `graph_dir()`. None while a launch is still reading its
    launch file (its nodes are coming, which ones is not known yet).
    """
    names: set[str] = set()
    starting = False
    for path, launcher, nodes in _announcements(directory):
        if not process_running(launcher):
            with contextlib.suppress(OSError):
                path.unlink()  # the launcher was killed; its children died with it
            continue
        if nodes is None:
            starting = True
        else:
            names.update(name for name, pid in nodes if process_running(pid))
    return None if starting else names
