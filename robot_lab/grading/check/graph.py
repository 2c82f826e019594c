"""Checks of the ROS graph: which nodes and topics run, what a topic carries, how often."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.check.base import (
    CheckError,
    callback_failed,
    judged,
    outside_the_kit,
    passed,
    student_frames,
    wait_until,
)

__all__ = [
    'graph_matches',
    'node_subscribes',
    'nodes_running',
    'responds',
    'topic_publishes',
    'topic_rate',
    'topics_exist',
    'wiring_is',
]


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


@judged
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
            'run the cell above that starts them, and read its output for errors',
        ) from None
    passed(f'{len(wanted)} node{"s" * (len(wanted) != 1)} running: {", ".join(wanted)}')


@judged
def topics_exist(names: Iterable[str], timeout: float = 10.0) -> None:
    """These topics are in the graph (`ros2 topic list` shows them)."""
    from robot_lab.graph.api import topic_list

    wanted = sorted('/' + n.lstrip('/') for n in names)

    def _all_there() -> bool:
        present = {name for name, _types in topic_list(settle=False)}
        return all(n in present for n in wanted)

    if not wait_until(_all_there, timeout):
        present = sorted(name for name, _types in topic_list(settle=False))
        raise CheckError(f'topics {", ".join(wanted)}',
                          f'the graph has {", ".join(present) or "no topics"}',
                          'start the nodes that publish or subscribe them')
    passed(f'topics exist: {", ".join(wanted)}')


def _type_hint(name: str, msg_type: str) -> str:
    package, _, kind = msg_type.partition('/msg/')
    return (f'publish {kind} on {name}: `from {package}.msg import {kind}`, '
            f'create_publisher({kind}, …) and a {kind}() message')


def _nobody_publishes(name: str) -> tuple[str, str]:
    """What a check says when no message comes because no one publishes `name`: a topic
    with a name close to it is the likely typo."""
    import difflib

    from robot_lab.graph.api import topic_list

    topics = {t: kinds for t, kinds in topic_list(settle=False)}
    # /sensor/temperature is no typo of /sensor/temperature_avg: a topic derived from it
    near = [t for t in difflib.get_close_matches(name, list(topics), n=3, cutoff=0.6)
            if t != name and not name.startswith(t + '_')]
    if near:
        return (f'nothing is published on {name}; there is {near[0]} '
                f'({", ".join(topics[near[0]])})',
                f'is {near[0]} a typo? Topic names must match exactly: {name}')
    return (f'no one publishes on {name}',
            f'is the publisher running, on that topic? `robot-lab topic info -v {name}`')


@judged
def topic_publishes(topic: str, msg_type: str | None = None,
                    where: Callable[[Any], bool] | None = None, timeout: float = 5.0,
                    description: str | None = None, hint: str | None = None) -> Any:
    """A message arrives on `topic` (of `msg_type`; satisfying `where`) within `timeout` s.

    `hint` is what to try when messages come but none is as described.

    """
    from robot_lab.graph.topics import echo_stream
    from robot_lab.messages import message_to_dict, type_name

    name = '/' + topic.lstrip('/')
    what = f'a message on {name}' + (f' {description}' if description else '')
    last: Any = None
    try:
        stream = echo_stream(name, None, timeout=timeout)
        try:
            for msg in stream:
                last = msg
                if msg_type is not None and type_name(msg) != msg_type:
                    raise CheckError(what, f'{name} carries {type_name(msg)}, not {msg_type}',
                                     _type_hint(name, msg_type))
                if where is None or where(msg):
                    passed(f'{name} publishes {type_name(msg)}' +
                           (f' {description}' if description else ''))
                    return
        finally:
            getattr(stream, 'close', lambda: None)()  # its subscription goes now, not at GC
    except RobotLabError:
        callback_failed(what)
        seen, try_ = _nobody_publishes(name)
        raise CheckError(what, seen, try_) from None
    callback_failed(what)
    if last is None:
        from robot_lab.graph.api import topic_info

        writers = sorted({e.node_name for e in topic_info(name).publishers})
        if writers:
            raise CheckError(what, f'{name} has a publisher ({", ".join(writers)}), but '
                             f'nothing arrived within {timeout:g} s',
                             'does your code call publish() (from a timer or a callback that '
                             'runs)?')
        seen, try_ = _nobody_publishes(name)
        raise CheckError(what, f'within {timeout:g} s nothing arrived: {seen}', try_)
    raise CheckError(what, f'within {timeout:g} s the last one was {message_to_dict(last)}',
                     hint or 'look at the node’s parameters and log output')


@judged
def topic_rate(topic: str, low: float, high: float, duration: float = 2.0,
               attempts: int = 2, enough: float = 1.0) -> None:
    """`topic` is published between `low` and `high` Hz (`ros2 topic hz`'s average).

    A window ends once its intervals span `enough` seconds (the whole `duration` for a
    slow or silent publisher): waiting out 2 s cost every rate check in the course a
    second. On a loaded machine DDS can deliver a burst that skews one short window, so a
    rate outside the band is measured again (up to `attempts` windows); a publisher that
    really runs at the wrong rate fails every one of them.
    """
    from robot_lab.graph.api import topic_hz

    name = '/' + topic.lstrip('/')
    rates: list[float] = []
    for _ in range(max(1, attempts)):
        try:
            stats = topic_hz(name, duration=duration, enough=enough)
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
    passed(f'{name} publishes at {low:g}–{high:g} Hz')


@judged
def graph_matches(nodes: Iterable[str], topics: Mapping[str, str], timeout: float = 5.0) -> None:
    """The running graph has exactly these nodes, and each topic carries its stated type."""
    from robot_lab.graph.api import node_list, topic_list

    wanted = sorted(nodes)
    if not wanted or not topics:
        empty = 'expected_nodes' if not wanted else 'expected_topics'
        raise CheckError(f'your {empty} filled in', f'{empty} is empty',
                         'write the full node names (a leading /) and, for each topic, its '
                         'type as package/msg/Type, from what your code creates')
    if not wait_until(lambda: sorted(node_list(settle=False)) == wanted, timeout):
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
    passed(f'{len(wanted)} nodes and {len(topics)} topics as you expected')


def _subscriptions(node: str) -> list[str] | None:
    """The topics `node` subscribes to now (None: not running), rclpy's own left out."""
    from robot_lab.graph.api import node_info

    try:
        info = node_info(node)
    except RobotLabError:
        return None
    return [name for name, _types in info.subscribers if name != '/parameter_events']


def _in_source(path: Path, topic: str) -> bool:
    text = path.read_text(encoding='utf-8') if path.is_file() else ''
    return f"'{topic}'" in text or f'"{topic}"' in text


@judged
def node_subscribes(node: str, topic: str, source: str | Path | None = None,
                    timeout: float = 10.0) -> None:
    """`node` subscribes to `topic` (`ros2 node info` lists it).

    Given the node's `source` file, a failure tells a name still wrong in the file from a
    node that started before the file was fixed (it runs the old code until restarted).
    """
    import difflib

    from robot_lab.graph.api import topic_info

    full = '/' + node.lstrip('/')
    want = f'{full} to subscribe to {topic}'
    found = wait_until(lambda: topic in (_subscriptions(full) or []), timeout)
    if found:
        passed(f'{full} subscribes to {topic}')
        return
    subs = _subscriptions(full)
    if subs is None:
        raise CheckError(want, f'{full} is not running',
                         'start the system (the launch cell above) and read its output')
    near = difflib.get_close_matches(topic, subs, n=1, cutoff=0.6)
    wrong = near[0] if near else None
    try:
        talkers = sorted(e.node_namespace.rstrip('/') + '/' + e.node_name
                         for e in topic_info(topic).publishers)
    except RobotLabError:
        talkers = []
    by = f' (published by {", ".join(talkers)})' if talkers else ''
    if wrong is None:
        raise CheckError(want, f'it subscribes to {", ".join(subs) or "nothing"}',
                         f'create_subscription(…, {topic!r}, …) in its code, then restart it')
    file = Path(source) if source is not None else None
    if file is not None and _in_source(file, topic) and not _in_source(file, wrong):
        raise CheckError(want, f'{file.name} says {topic!r} now, but the running {full} still '
                         f'subscribes to {wrong}: it started before your fix',
                         'a node runs the code it started with: run the cell that restarts '
                         'the system (system.shutdown(), then robot_lab.launch(...)); no '
                         'kernel restart is needed')
    where = f' in {file.name}' if file is not None else ''
    raise CheckError(want, f'it subscribes to {wrong}, not {topic}{by}',
                     f'is {wrong} a typo? Topic names match exactly: use {topic!r} in the '
                     f'create_subscription{where}, then restart the system')


def _raised(err: BaseException) -> str:
    return type(err).__name__ + (f': {err}' if str(err) else '')


@judged
def wiring_is(wiring: Callable[[str], Any], topic: str, publishers: list[str],
              subscribers: list[str]) -> None:
    """The student's `wiring(topic)` returns (publishers, subscribers) as the graph has them."""
    want = (sorted(publishers), sorted(subscribers))
    try:
        # the graph may still be settling: ask again for a few seconds before judging
        wait_until(lambda: tuple(wiring(topic)) == want, 5.0)
        got = wiring(topic)
    except Exception as err:
        raise CheckError(f'wiring({topic!r}) to return {want}',
                         f'it raised {_raised(err)}',
                         'replace the placeholder in your answer cell with your code'
                         if isinstance(err, NotImplementedError) else
                         'run it in the answer cell and read the error line',
                         student_frames(err, outside_the_kit)) from None
    if got is None or tuple(got) != want:
        raise CheckError(f'wiring({topic!r}) to return {want}', f'it returned {got!r}',
                         'full names: namespace + "/" + name; sorted lists; publishers first')
    passed(f'{topic}: {", ".join(want[0])} → {", ".join(want[1])}')


@judged
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
