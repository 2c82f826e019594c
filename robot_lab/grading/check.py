"""What a notebook's check cell calls: real checks of the running system, one line each.

Every check looks at the real graph (nodes, topics, parameters, logs, files), waits a
bounded time for it to become true, prints one deterministic `✓ …` line when it is, and
otherwise raises CheckError: what was expected, what was seen, what to try. A failing
check is a failing cell, so nbval fails with it. Checks return nothing: a check cell's
output is only its ✓ lines, the same on every run (nbval compares it).
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError

__all__ = [
    'CheckError',
    'bag_contains',
    'eventually',
    'files_exist',
    'logs_contain',
    'no_errors',
    'nodes_running',
    'package_built',
    'param_equals',
    'param_file_accepted',
    'plot_shows',
    'topic_publishes',
    'topic_rate',
    'topics_exist',
]


class CheckError(AssertionError):
    """A check cell's expectation did not hold; the message says what to try."""

    def __init__(self, expected: str, seen: str, hint: str) -> None:
        self.expected, self.seen, self.hint = expected, seen, hint
        super().__init__(f'✗ expected {expected}; {seen}. Try: {hint}')


def _ok(text: str) -> None:
    print(f'✓ {text}')


def _wait(probe: Callable[[], Any], timeout: float, interval: float = 0.1) -> Any:
    """Poll `probe` until it returns something truthy or `timeout` passes (then its last)."""
    deadline = time.monotonic() + timeout
    while True:
        value = probe()
        if value or time.monotonic() >= deadline:
            return value
        time.sleep(interval)


def eventually(condition: Callable[[], Any], what: str, timeout: float = 5.0,
               hint: str = 'run the cells above again, in order') -> None:
    """`condition()` becomes truthy within `timeout` s."""
    value = _wait(condition, timeout)
    if not value:
        raise CheckError(what, f'still not true after {timeout:g} s', hint)
    _ok(what)


def nodes_running(names: Iterable[str], timeout: float = 10.0) -> None:
    """These nodes are in the graph (`ros2 node list` shows them)."""
    from robot_lab.graph.api import node_list, wait_for_nodes

    wanted = sorted('/' + n.lstrip('/') for n in names)
    try:
        wait_for_nodes(wanted, timeout=timeout)
    except RobotLabError:
        present = node_list(settle=False)
        missing = [n for n in wanted if n not in present]
        raise CheckError(
            f'nodes {", ".join(wanted)} running',
            f'missing {", ".join(missing)} (running now: {", ".join(present) or "none"})',
            'start them (the launch cell above) and look at their output for errors',
        ) from None
    _ok(f'{len(wanted)} node{"s" * (len(wanted) != 1)} running: {", ".join(wanted)}')


def topics_exist(names: Iterable[str], timeout: float = 10.0) -> None:
    """These topics are in the graph (`ros2 topic list` shows them)."""
    from robot_lab.graph.api import topic_list

    wanted = sorted('/' + n.lstrip('/') for n in names)

    def _all_there() -> bool:
        present = {name for name, _types in topic_list(settle=False)}
        return all(n in present for n in wanted)

    if not _wait(_all_there, timeout):
        present = sorted(name for name, _types in topic_list(settle=False))
        raise CheckError(f'topics {", ".join(wanted)}',
                          f'the graph has {", ".join(present) or "no topics"}',
                          'start the nodes that publish or subscribe them')
    _ok(f'topics exist: {", ".join(wanted)}')


def topic_publishes(topic: str, msg_type: str | None = None,
                    where: Callable[[Any], bool] | None = None, timeout: float = 5.0,
                    description: str | None = None) -> Any:
    """A message arrives on `topic` (of `msg_type`; satisfying `where`) within `timeout` s.

    Returns the first message that matched.
    """
    from robot_lab.graph.topics import echo_stream
    from robot_lab.messages import message_to_dict, type_name

    name = '/' + topic.lstrip('/')
    what = f'a message on {name}' + (f' {description}' if description else '')
    last: Any = None
    try:
        for msg in echo_stream(name, None, timeout=timeout):
            last = msg
            if msg_type is not None and type_name(msg) != msg_type:
                raise CheckError(what, f'{name} carries {type_name(msg)}, not {msg_type}',
                                  'check the publisher’s message type')
            if where is None or where(msg):
                _ok(f'{name} publishes {type_name(msg)}' +
                    (f' {description}' if description else ''))
                return
    except RobotLabError as err:
        raise CheckError(what, f'none came: {err.message}',
                          f'is the publisher running? `robot-lab topic info -v {name}`') from None
    seen = 'nothing arrived' if last is None else f'the last one was {message_to_dict(last)}'
    raise CheckError(what, f'within {timeout:g} s {seen}',
                      'look at the node’s parameters and log output')


def topic_rate(topic: str, low: float, high: float, duration: float = 2.0,
               attempts: int = 2) -> None:
    """`topic` is published between `low` and `high` Hz (`ros2 topic hz`'s average).

    On a loaded machine DDS can deliver a burst that skews one short window, so a rate
    outside the band is measured again (up to `attempts` windows); a publisher that really
    runs at the wrong rate fails every one of them.
    """
    from robot_lab.graph.api import topic_hz

    name = '/' + topic.lstrip('/')
    rates: list[float] = []
    for _ in range(max(1, attempts)):
        try:
            stats = topic_hz(name, duration=duration)
        except RobotLabError as err:
            raise CheckError(f'{name} at {low:g}–{high:g} Hz', err.message,
                              f'is the publisher running? `robot-lab topic info -v {name}`'
                              ) from None
        rates.append(stats.rate)
        if low <= stats.rate <= high:
            break
    else:
        measured = ', '.join(f'{r:.1f}' for r in rates)
        raise CheckError(f'{name} at {low:g}–{high:g} Hz', f'it runs at {measured} Hz',
                          'check the rate parameter of the publishing node')
    _ok(f'{name} publishes at {low:g}–{high:g} Hz')


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=1e-9)
        except (TypeError, ValueError):
            return False
    return bool(a == b)


def param_equals(node: str, name: str, value: Any, timeout: float = 5.0) -> None:
    """`ros2 param get <node> <name>` gives `value` (floats compared with tolerance)."""
    from robot_lab.graph.api import param_get

    full = '/' + node.lstrip('/')
    got: list[Any] = []

    def _probe() -> bool:
        try:
            got.append(param_get(full, name))
        except RobotLabError as err:
            got.append(err)
            return False
        return _same(got[-1], value)

    if not _wait(_probe, timeout, interval=0.2):
        last = got[-1] if got else None
        seen = last.message if isinstance(last, RobotLabError) else f'it is {last!r}'
        raise CheckError(f'{full} {name} = {value!r}', seen,
                          'set it (param set, a slider, or the parameter file) and check '
                          'the node accepted it')
    _ok(f'{full} {name} = {value!r}')


def param_file_accepted(path: str | Path) -> None:
    """rcl's rules accept the parameter file (what a node given `--params-file` reads)."""
    from robot_lab.params import load_param_file

    try:
        sections = load_param_file(path)
    except RobotLabError as err:
        raise CheckError(f'{Path(path).name} accepted by rcl', f'it is refused: {err.message}',
                         err.fix or 'nest the values under `<node name>: ros__parameters:`') \
            from None
    if not sections:
        raise CheckError(f'{Path(path).name} to set parameters', 'it has no node section',
                         'add `/**:` (or a node name) with `ros__parameters:` under it')
    summary = '; '.join(f'{node} sets {", ".join(sorted(values))}'
                        for node, values in sections.items())
    _ok(f'rcl accepts {Path(path).name}: {summary}')


def logs_contain(source: Any, pattern: str, timeout: float = 10.0) -> None:
    """A log line matching `pattern` (regex) shows up in a launch's output or a console."""
    regex = re.compile(pattern)

    def _lines() -> list[str]:
        if hasattr(source, 'logs'):
            return list(source.logs())
        if hasattr(source, 'lines'):
            return list(source.lines(level='DEBUG'))
        raise TypeError(f'logs_contain() needs a LaunchHandle or a Console, not {source!r}')

    found = _wait(lambda: next((line for line in _lines() if regex.search(line)), None),
                  timeout)
    if not found:
        tail = '\n'.join(_lines()[-8:])
        raise CheckError(f'a log line matching {pattern!r}',
                          f'within {timeout:g} s the last lines were:\n{tail}\n',
                          'read the output above for errors (a process that died says why)')
    _ok(f'the log shows {regex.pattern!r}')


def no_errors(launch: Any) -> None:
    """A launch's processes are all running and none logged at ERROR or FATAL."""
    errors = launch.logs(level='ERROR')
    dead = [f'{p.label} ({p.state}, exit code {p.exit_code})' for p in launch.processes
            if p.state != 'running']
    if errors or dead:
        seen = '; '.join([*(f'{d} stopped' for d in dead), *errors[-3:]])
        raise CheckError('every process running and no error messages', seen,
                         'read the first error line: it names the file and what to fix')
    _ok(f'{len(launch.processes)} processes running, no error messages')


def files_exist(root: str | Path, paths: Iterable[str]) -> None:
    """Each of `paths` exists under `root` (a folder path ends with '/')."""
    base = Path(root)
    wanted = list(paths)
    missing = []
    for rel in wanted:
        target = base / rel
        ok = target.is_dir() if rel.endswith('/') else target.is_file()
        if not ok:
            missing.append(rel)
    if missing:
        raise CheckError(f'{", ".join(wanted)} in {base.name}/', f'missing {", ".join(missing)}',
                          'run the cells that create them, in order')
    _ok(f'{base.name}/ has {", ".join(wanted)}')


def package_built(workspace: str | Path, package: str,
                  executables: Iterable[str] = ()) -> None:
    """colcon installed `package` (ament index marker, package.xml, its executables)."""
    prefix = Path(workspace) / 'install' / package
    need = [Path('share/ament_index/resource_index/packages') / package,
            Path('share') / package / 'package.xml',
            *(Path('lib') / package / exe for exe in executables)]
    missing = [str(p) for p in need if not (prefix / p).exists()]
    if missing:
        raise CheckError(f'{package} built and installed in install/{package}',
                          f'missing {", ".join(missing)}',
                          'read the build output above; fix the first error and build again')
    exes = list(executables)
    _ok(f'{package} is installed' + (f' with {", ".join(exes)}' if exes else ''))


def plot_shows(plot: Any, path: str, where: Callable[[float], bool], description: str,
               timeout: float = 5.0, last: float = 1.0) -> None:
    """The plotted values of `path` in its `last` seconds all satisfy `where` (waits)."""

    def _probe() -> list[float] | None:
        values = plot.values(path, last=last)
        return values if values and all(where(v) for v in values) else None

    values = _wait(_probe, timeout)
    if not values:
        recent = plot.values(path, last=last)
        seen = (f'the last values were {", ".join(f"{v:.2f}" for v in recent[-5:])}'
                if recent else 'no samples arrived')
        raise CheckError(f'{path} {description}', seen,
                          'check the parameter you changed was accepted (✓ next to the slider)')
    _ok(f'{path} {description}')


def bag_contains(bag: str | Path, counts: Mapping[str, int]) -> None:
    """The bag holds at least `counts[topic]` messages of each topic (`ros2 bag info`)."""
    from robot_lab.bag.info import bag_info

    try:
        info = bag_info(bag)
    except RobotLabError as err:
        raise CheckError(f'a bag at {bag}', err.message, 'record it first (the cell above)') \
            from None
    have = {t.name: t.count for t in info.topics}
    short = {t: have.get(t, 0) for t, n in counts.items() if have.get(t, 0) < n}
    if short:
        raise CheckError(
            ', '.join(f'≥ {n} messages on {t}' for t, n in counts.items()),
            'the bag has ' + ', '.join(f'{c} on {t}' for t, c in short.items()),
            'record while the nodes run, for a few seconds')
    _ok('the bag holds ' + ', '.join(f'≥ {n} messages on {t}' for t, n in counts.items()))
