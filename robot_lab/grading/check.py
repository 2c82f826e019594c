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
    'answered',
    'bag_contains',
    'eventually',
    'files_exist',
    'logs_contain',
    'no_errors',
    'node_starts',
    'nodes_running',
    'package_built',
    'param_equals',
    'param_file_accepted',
    'plot_shows',
    'setup_py',
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


def _deaths(launch: Any) -> list[str]:
    """`label exited 1: <its last output line>` for each process of `launch` that stopped."""
    notes = []
    lines = list(launch.logs()) if launch is not None else []
    for proc in getattr(launch, 'processes', []):
        if proc.state == 'running':
            continue
        own = [line[len(proc.label) + 3:] for line in lines
               if line.startswith(f'[{proc.label}] ')]
        last = own[-1].strip() if own else 'no output'
        notes.append(f'{proc.label} stopped (exit code {proc.exit_code}): {last}')
    return notes


def nodes_running(names: Iterable[str], timeout: float = 10.0, launch: Any = None) -> None:
    """These nodes are in the graph (`ros2 node list` shows them).

    Given the `launch` that started them, a failure also says which of its processes
    stopped and the last line each printed (a node that refused a parameter says why).
    """
    from robot_lab.graph.api import node_list, wait_for_nodes

    wanted = sorted('/' + n.lstrip('/') for n in names)
    try:
        wait_for_nodes(wanted, timeout=timeout)
    except RobotLabError:
        present = node_list(settle=False)
        missing = [n for n in wanted if n not in present]
        deaths = _deaths(launch)
        raise CheckError(
            f'nodes {", ".join(wanted)} running',
            f'missing {", ".join(missing)} (running now: {", ".join(present) or "none"})'
            + ''.join(f'; {d}' for d in deaths),
            'read why it stopped: the last line above names the cause' if deaths else
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
        from robot_lab.graph.api import node_list

        last = got[-1] if got else None
        if isinstance(last, RobotLabError) and full not in node_list(settle=False):
            raise CheckError(f'{full} {name} = {value!r}', f'{full} is not running',
                             'start it, and read its output: a node that refuses a value '
                             'from the parameter file stops at start and says why')
        seen = last.message if isinstance(last, RobotLabError) else f'it is {last!r}'
        hint = 'set it (param set, a slider, or the parameter file) and check the node ' \
            'accepted it'
        if isinstance(last, int | float) and not isinstance(last, bool) and \
                isinstance(value, float) != isinstance(last, float):
            hint = (f'the node holds {type(last).__name__} {last!r}, the check expects '
                    f'{type(value).__name__} {value!r}: in YAML `22` is an integer and '
                    '`22.0` a double')
        raise CheckError(f'{full} {name} = {value!r}', seen, hint)
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


# --- the student's own files -------------------------------------------------------------

# What nbgrader's ClearSolutions leaves where an answer was (`robot-lab course release`).
_PLACEHOLDERS = ('YOUR CODE HERE', 'raise NotImplementedError')


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
    _ok(f'{file.name} holds {what}')


def node_starts(module: str, cls: str, package: str = 'my_robot_system',
                hint: str = 'read the line named above in your answer cell, fix it, run the '
                            'cell and then this check again') -> Any:
    """The student's node class imports afresh, constructs, and spins in the kernel's session.

    The module is reloaded, so an edited and re-run `%%writefile` cell counts without a
    kernel restart. Returns the node (stop it with `session.remove_node` + `destroy_node`).
    """
    import importlib
    import sys
    import traceback

    from robot_lab.context import session

    name = f'{package}.{module}'
    what = f'{cls}() from {module}.py to start'
    session()  # the context the node joins
    try:
        importlib.invalidate_caches()
        loaded = importlib.reload(sys.modules[name]) if name in sys.modules \
            else importlib.import_module(name)
        node = getattr(loaded, cls)()
    except Exception as err:
        frames = traceback.extract_tb(err.__traceback__)
        where = next((f'{Path(f.filename).name} line {f.lineno}' for f in reversed(frames)
                      if f.filename.endswith(f'{module}.py')), name)
        text = f'{type(err).__name__}' + (f': {err}' if str(err) else '')
        if isinstance(err, NotImplementedError):
            text += ' (the placeholder is still there)'
        raise CheckError(what, f'{text} at {where}', hint) from None
    session().add_node(node)
    _ok(f'{cls} runs as node /{node.get_name()}')
    return node


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
                         f'setup.py declares {", ".join(repr(d) for d in declared) or "none"}',
                         "add one 'name = my_robot_system.module:main' string per node to "
                         "entry_points={'console_scripts': [...]}")
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
    _ok('setup.py declares ' + ', '.join(executables) + (f' and installs {where}' if where else ''))


# --- the student's parameters: descriptors and callbacks ---------------------------------

def stop_node(node: Any) -> None:
    """Take a node `node_starts` returned out of the kernel's session and destroy it."""
    from robot_lab.context import session

    session().remove_node(node)
    node.destroy_node()


def param_described(node: str, name: str, low: float | None = None,
                    high: float | None = None) -> None:
    """`ros2 param describe` shows a description and, given `low`/`high`, that range."""
    from robot_lab.graph.api import param_describe

    full = '/' + node.lstrip('/')
    want = f'{full} {name} described' + (f' with the range {low:g} … {high:g}'
                                          if low is not None and high is not None else '')
    try:
        d = param_describe(full, name)
    except RobotLabError as err:
        raise CheckError(want, err.message, 'declare it with declare_parameter(name, default, '
                                            'ParameterDescriptor(...))') from None
    rng = 'no range' if d.min_value is None else f'the range {d.min_value:g} … {d.max_value:g}'
    if not d.description or (low is not None and (d.min_value, d.max_value) != (low, high)):
        raise CheckError(want, f'its description is {d.description!r} with {rng}',
                         'pass ParameterDescriptor(description=..., integer_range=[...] or '
                         'floating_point_range=[...]) as the third argument of declare_parameter')
    _ok(want)


def param_refused(node: str, name: str, value: Any, reason: str = '') -> None:
    """Setting `name` to `value` is refused (with a reason naming `reason`), value kept."""
    from robot_lab.graph.api import param_get
    from robot_lab.graph.parameters import set_parameters

    full = '/' + node.lstrip('/')
    before = param_get(full, name)
    (result,) = set_parameters(full, {name: value})
    after = param_get(full, name)
    want = f'{full} to refuse {name} = {value!r}' + (f' with a reason about {reason}'
                                                      if reason else '')
    if result.successful or not result.reason or reason not in result.reason:
        seen = ('it accepted it' if result.successful else
                f'it refused it with the reason {result.reason!r}')
        raise CheckError(want, seen, 'in your on-set callback return SetParametersResult('
                                     "successful=False, reason='...') when the value breaks "
                                     'the rule, before storing anything')
    if not _same(before, after):
        raise CheckError(want, f'it refused, but {name} changed from {before!r} to {after!r}',
                         'validate every value before you store any of them')
    _ok(f'{full} refuses {name} = {value!r}: {result.reason}')


def param_applied(node: str, name: str, value: Any, topic: str,
                  where: Callable[[Any], bool], description: str,
                  timeout: float = 5.0) -> None:
    """Setting `name` to `value` is accepted and then `topic` carries a message `where` likes."""
    from robot_lab.graph.parameters import set_parameters

    full = '/' + node.lstrip('/')
    (result,) = set_parameters(full, {name: value})
    if not result.successful:
        raise CheckError(f'{full} to accept {name} = {value!r}',
                         f'it refused: {result.reason or "(no reason given)"}',
                         'a value in range that breaks no rule must be accepted: return '
                         'SetParametersResult(successful=True)')
    try:
        topic_publishes(topic, where=where, timeout=timeout, description=description)
    except CheckError as err:
        raise CheckError(f'{name} = {value!r} to take effect: {topic} {description}',
                         err.seen, 'store the new value in your callback (self.… = '
                                   'param.value); reading it in __init__ only is not enough'
                         ) from None


# --- the capstone's deliverable: a package of the student's own --------------------------

def responds(in_topic: str, msg_type: str, values: Mapping[str, Any], out_topic: str,
             where: Callable[[Any], bool], description: str, timeout: float = 5.0) -> None:
    """While `values` are published on `in_topic` (10 Hz), `out_topic` carries a match."""
    import threading

    from robot_lab.graph.api import publish

    stop = threading.Event()

    def _feed() -> None:
        while not stop.is_set():
            publish(in_topic, msg_type, dict(values), wait_for_subscriber=0.0)
            stop.wait(0.1)

    feeder = threading.Thread(target=_feed, daemon=True)
    feeder.start()
    try:
        topic_publishes(out_topic, where=where, timeout=timeout, description=description)
    except CheckError as err:
        raise CheckError(f'{out_topic} {description} while {in_topic} carries {dict(values)}',
                         err.seen, 'compute the command from the message in your callback and '
                                   'publish it there, once per message') from None
    finally:
        stop.set()
        feeder.join(timeout=2.0)


def param_count(path: str | Path, at_least: int) -> None:
    """The parameter file sets at least `at_least` parameters (all node sections together)."""
    from robot_lab.params import load_param_file

    sections = load_param_file(path)
    names = sorted({f'{node}/{name}' for node, values in sections.items() for name in values})
    if len(names) < at_least:
        raise CheckError(f'at least {at_least} parameters in {Path(path).name}',
                         f'it sets {len(names)}: {", ".join(names) or "none"}',
                         'add the parameters your nodes declare, under their node sections')
    _ok(f'{Path(path).name} sets {len(names)} parameters')


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
                             'one <node pkg="…" exec="…" name="…"> per node')
        if not any(p.get('from') for p in el.iter('param')):
            raise CheckError(f'node {name} to load the parameter file',
                             'it has no <param from="…"/>',
                             'add <param from="$(find-pkg-share PACKAGE)/config/FILE.yaml"/>')
    _ok(f'{file.name} starts {", ".join(nodes)}, each with a parameter file')


def readme_explains(path: str | Path, commands: Iterable[str]) -> None:
    """The README exists and shows these commands (build, launch …)."""
    file = Path(path)
    text = file.read_text(errors='replace') if file.is_file() else ''
    missing = [c for c in commands if c not in text]
    if not text or missing:
        raise CheckError(f'{file.name} with the commands {", ".join(commands)}',
                         'there is no README' if not text else f'it lacks {", ".join(missing)}',
                         'write how to build and launch your package, commands in code blocks')
    _ok(f'{file.name} shows {", ".join(commands)}')


def full_marks(report: str | Path) -> None:
    """`robot-lab grade -o REPORT` gave every submission in it full marks."""
    import csv

    grades = Path(report) / 'grades.csv'
    if not grades.is_file():
        raise CheckError(f'a grade report in {Path(report).name}/', 'there is no grades.csv',
                         'run the grading cell above and read its output')
    with grades.open(newline='') as f:
        rows = list(csv.DictReader(f))
    short = [f'{r["student"]}: {r["score"]}/{r["max_score"]}' for r in rows
             if float(r['score']) < float(r['max_score'])]
    if not rows or short:
        lost = [k for r in rows for k, v in r.items()
                if k not in ('student', 'score', 'max_score') and v in ('0', '0.0')]
        raise CheckError('full marks from the grader', '; '.join(short) or 'no rows',
                         f'read the feedback of {", ".join(lost) or "each check"} above')
    _ok(', '.join(f'{r["student"]}: {r["score"]}/{r["max_score"]}' for r in rows))


def command_prints(command: str, pattern: str, seconds: float = 5.0,
                   cwd: str | Path | None = None) -> None:
    """`command` (bash, as typed in a terminal) prints a line matching `pattern` within
    `seconds`; then it gets Ctrl-C, and everything it started is stopped."""
    import os
    import signal
    import subprocess

    if not command.strip():
        raise CheckError(f'a command that prints {pattern!r}', 'the command is empty',
                         'write the command line in your answer cell')
    proc = subprocess.Popen(['bash', '-c', command], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=seconds)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGINT)  # the Ctrl-C a terminal would send
        try:
            out, _ = proc.communicate(timeout=5.0)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, _ = proc.communicate()
    lines = out.splitlines()
    if not any(re.search(pattern, line) for line in lines):
        tail = '\n'.join(lines[-4:]) or '(no output)'
        raise CheckError(f'`{command}` to print {pattern!r}', f'it printed:\n{tail}\n',
                         'read the last line: it names what is missing and how to fix it')
    _ok(f'`{command}` prints {pattern!r}')


def graph_matches(nodes: Iterable[str], topics: Mapping[str, str], timeout: float = 5.0) -> None:
    """The running graph has exactly these nodes, and each topic carries its stated type."""
    from robot_lab.graph.api import node_list, topic_list

    wanted = sorted(nodes)
    if not _wait(lambda: sorted(node_list(settle=False)) == wanted, timeout):
        seen = sorted(node_list(settle=False))
        raise CheckError(f'the nodes {", ".join(wanted)}', f'the graph has {", ".join(seen)}',
                         'node names are the launch file’s name= attributes, with a leading /')
    types = {name: kinds for name, kinds in topic_list(settle=False)}
    for topic, kind in topics.items():
        if kind not in types.get(topic, []):
            real = types.get(topic)
            raise CheckError(f'{topic} of type {kind}',
                             f'{topic} is {real[0]}' if real else f'there is no topic {topic}',
                             'types are written package/msg/Type, e.g. std_msgs/msg/Float32')
    _ok(f'{len(wanted)} nodes and {len(topics)} topics as you expected')


def wiring_is(wiring: Callable[[str], Any], topic: str, publishers: list[str],
              subscribers: list[str]) -> None:
    """The student's `wiring(topic)` returns (publishers, subscribers) as the graph has them."""
    want = (sorted(publishers), sorted(subscribers))
    try:
        # the graph may still be settling: ask again for a few seconds before judging
        _wait(lambda: tuple(wiring(topic)) == want, 5.0)
        got = wiring(topic)
    except Exception as err:
        raise CheckError(f'wiring({topic!r}) to return {want}',
                         f'it raised {type(err).__name__}: {err}',
                         'run it in the answer cell and read the error line') from None
    if got is None or tuple(got) != want:
        raise CheckError(f'wiring({topic!r}) to return {want}', f'it returned {got!r}',
                         'full names: namespace + "/" + name; sorted lists; publishers first')
    _ok(f'{topic}: {", ".join(want[0])} → {", ".join(want[1])}')


def first_time(bag: str | Path, topic: str, field: str, where: Callable[[float], bool],
               answer: Any) -> None:
    """`answer` is the bag time (s) of the first `topic` message whose `field` satisfies
    `where`, as `robot_lab.read_topic` gives times."""
    from robot_lab.bag.read import read_topic

    columns = read_topic(bag, topic, [field])
    times = [t for t, v in zip(columns.t, columns[field], strict=True) if where(v)]
    if not times:
        raise CheckError(f'a {topic} message in the bag whose {field} matches',
                         f'none of its {len(columns)} messages does',
                         'record again: the parameter change must fall inside the recording')
    if not isinstance(answer, int | float) or not math.isclose(answer, times[0], abs_tol=1e-6):
        raise CheckError(f'{times[0]:.2f} s (the first match)', f'your answer is {answer!r}',
                         'take the time of the first matching message, not the last or a count')
    _ok(f'that is the time of the first {topic} message whose {field} matches')
