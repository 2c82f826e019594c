"""Checks of tf2 in the running graph: a frame where it should be, a turtle that follows
another, and a student's lookup judged on a listener that has just started.

Each check listens with a fresh tf2 Buffer and TransformListener (a buffer kept from an
earlier run would still hold a frame the student has since renamed) and, beside it, reads
/tf and /tf_static raw: a transform tf2 refuses (a quaternion that is not normalised) never
reaches a buffer, and only the raw message shows what the student sent.
"""

from __future__ import annotations

import difflib
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robot_lab.grading.check.base import (
    CheckError,
    judged,
    outside_the_kit,
    passed,
    student_frames,
    wait_until,
)

__all__ = ['echo_prints', 'follows', 'lookup_returns', 'time_travel', 'transform_is']

# geometry2's BufferCore refuses a rotation whose squared length is further from 1 than this.
_NORMALISED = 1e-2


@dataclass(frozen=True)
class _Edge:
    """The last transform seen for one child frame, as it was sent."""

    parent: str
    child: str
    stamp_ns: int
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]
    static: bool


class _Tree:
    """A node in the kernel's session with a fresh Buffer, its TransformListener, and raw
    subscriptions to /tf and /tf_static (the last transform per child frame)."""

    def __init__(self) -> None:
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from tf2_msgs.msg import TFMessage

        from robot_lab.rclpy_session import session
        from robot_lab.tf2.buffer import Buffer
        from robot_lab.tf2.listener import TransformListener

        self.session = session()
        self.node = self.session.hidden_node(f'check_tf_{next(_COUNT)}')
        self.edges: dict[str, _Edge] = {}
        self._lock = threading.Lock()
        static = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                            reliability=ReliabilityPolicy.RELIABLE)
        self.node.create_subscription(TFMessage, '/tf', lambda m: self._raw(m, False), 100)
        self.node.create_subscription(TFMessage, '/tf_static', lambda m: self._raw(m, True),
                                      static)
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self.node)
        self.session.add_node(self.node)

    def _raw(self, msg: Any, static: bool) -> None:
        with self._lock:
            for t in msg.transforms:
                v, q = t.transform.translation, t.transform.rotation
                self.edges[t.child_frame_id] = _Edge(
                    t.header.frame_id, t.child_frame_id, _stamp_ns(t.header.stamp), (v.x, v.y, v.z),
                    (q.x, q.y, q.z, q.w), static)

    def edge(self, child: str) -> _Edge | None:
        with self._lock:
            return self.edges.get(child)

    def all_edges(self) -> list[_Edge]:
        with self._lock:
            return list(self.edges.values())

    def now_ns(self) -> int:
        return int(self.node.get_clock().now().nanoseconds)

    def close(self) -> None:
        self.listener.unregister()
        self.session.remove_node(self.node)
        self.node.destroy_node()


_COUNT = iter(range(1, 1 << 30))


def _yaw(q: tuple[float, float, float, float]) -> float:
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _unit(q: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    n = math.sqrt(sum(c * c for c in q))
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def _vec(v: tuple[float, ...]) -> str:
    return '(' + ', '.join(f'{c:.3f}' for c in v) + ')'


def _raised(err: BaseException) -> str:
    return type(err).__name__ + (f': {err}' if str(err) else '')


def _frame_names(tree: _Tree, parent: str, child: str, waited: float,
                 sure: float | None = None) -> tuple[str, str] | None:
    """What is wrong with the frame names or the wiring of `parent` → `child`, if anything.

    `sure` (s since the check began): only a fault that waiting cannot mend, else None:
    what was sent is wrong, for a second or more (a misspelt name: three, as another frame
    may be heard before the right one).
    """
    edges = tree.all_edges()
    if sure is not None and (sure < 1.0 or not edges):
        return None
    if not edges:
        return (f'nothing on /tf or /tf_static within {waited:g} s',
                'is your broadcaster running, and does it call sendTransform(t) (from a '
                'callback that runs)?')
    mine = tree.edge(child)
    if mine is None:
        swapped = [e for e in edges if e.parent == child]
        if any(e.child == parent for e in swapped):
            return (f'the transform goes {child} → {parent} (header.frame_id {child!r}, '
                    f'child_frame_id {parent!r})',
                    f'header.frame_id is the parent frame ({parent!r}), child_frame_id the '
                    f'frame you add ({child!r})')
        seen = ', '.join(sorted(f'{e.parent} → {e.child}' for e in edges))
        near = difflib.get_close_matches(child, [e.child for e in edges], n=1, cutoff=0.5)
        if sure is not None and (not near or sure < 3.0):  # the frame may still come
            return None
        return (f'no frame {child!r} on /tf or /tf_static (they carry {seen})',
                (f'is {near[0]!r} meant to be {child!r}? ' if near else '') +
                'frame names must match exactly, with no leading /: child_frame_id names '
                'the frame you add')
    if mine.parent != parent:
        return (f'{child!r} has the parent {mine.parent!r}, not {parent!r}',
                f"header.frame_id = '{parent}': the frame {child} is attached to")
    norm2 = sum(c * c for c in mine.rotation)
    if math.isnan(norm2) or norm2 < 1e-12:  # nothing to normalise: every listener drops it
        return (f'{parent} → {child} has the rotation {_vec(mine.rotation)}: tf2 ignores it '
                '(TF_NAN_INPUT, TF_DENORMALIZED_QUATERNION)',
                'a rotation is a unit quaternion: x=y=z=0.0, w=1.0 for none')
    if abs(norm2 - 1.0) > _NORMALISED:  # tf2::Transform normalises it: another rotation
        return (f'{parent} → {child} has the rotation {_vec(mine.rotation)}, of length '
                f'{math.sqrt(norm2):.3f}, not 1: tf2 normalises it, and the frame turns by '
                f'yaw {_yaw(_unit(mine.rotation)):.3f}',
                'write a unit quaternion: turn roll, pitch and yaw into one with '
                'quaternion_from_euler (x=y=z=0.0, w=1.0 for no rotation)')
    return None


def _stale(tree: _Tree, child: str, failure: BaseException) -> tuple[str, str] | None:
    """A lookup at the time now failed because `child`'s transforms are stamped long ago."""
    mine = tree.edge(child)
    if mine is None or mine.static:
        return None
    age = (tree.now_ns() - mine.stamp_ns) / 1e9
    if age <= 1.0:
        return None
    return (f'its stamp is {mine.stamp_ns / 1e9:.3f} s, {age:.0f} s before now, so a lookup '
            f'at the time now fails: {failure}',
            'stamp each transform with the time now: '
            't.header.stamp = self.get_clock().now().to_msg()')


@judged
def transform_is(parent: str, child: str, translation: tuple[float, float, float] | None = None,
                 yaw: float | None = None, command: str | None = None,
                 cwd: str | Path | None = None, recent: bool = False, timeout: float = 10.0,
                 tolerance: float = 1e-3, hint: str | None = None) -> None:
    """`child` is in the running TF tree under `parent`, at `translation` (m) and `yaw`
    (rad), as a fresh listener sees it (while `command`, if given, runs in a terminal).

    `recent`: looked up at the current time (less 0.3 s), as a listener that uses the
    stamp of a measurement does; a broadcaster must stamp its transforms with the time now.
    A fault in what was sent (names, parent, quaternion, stamp) fails as soon as it is sure.
    """
    import rclpy
    from rclpy.duration import Duration

    from robot_lab.grading.check.output import _Terminal

    what = f'{child!r} under {parent!r}' + (f' at {_vec(translation)}' if translation else '') \
        + (f' with yaw {yaw:.3f}' if yaw is not None else '') \
        + (', at the current time' if recent else '')
    terminal = _Terminal(command, cwd) if command else None
    tree = _Tree()
    failures: list[BaseException] = []
    got: list[Any] = []
    verdict: list[tuple[str, str]] = []
    start = time.monotonic()

    def _matches(t: Any) -> bool:
        v, q = t.transform.translation, t.transform.rotation
        here = (v.x, v.y, v.z)
        ok = translation is None or all(abs(a - b) <= tolerance
                                        for a, b in zip(here, translation, strict=True))
        turn = _yaw((q.x, q.y, q.z, q.w))
        return ok and (yaw is None or abs(math.remainder(turn - yaw, math.tau)) <= tolerance)

    def _looked_up() -> bool:
        when = rclpy.time.Time()
        if recent:
            when = rclpy.time.Time(nanoseconds=tree.now_ns() - 300_000_000,
                                   clock_type=tree.node.get_clock().clock_type)
        try:
            t = tree.buffer.lookup_transform(parent, child, when, Duration())
        except Exception as err:  # tf2's exceptions: kept to say why, below
            failures[:] = [err]
            return False
        failures.clear()
        got[:] = [t]
        # a lookup also succeeds through the inverse, or with a quaternion tf2 normalised:
        # the transform as sent must be right too
        return _matches(t) and _frame_names(tree, parent, child, timeout) is None

    def _probe() -> bool:
        if _looked_up():
            return True
        elapsed = time.monotonic() - start
        sure = _frame_names(tree, parent, child, timeout, sure=elapsed)
        if sure is None and recent and failures and elapsed >= 1.0:
            sure = _stale(tree, child, failures[0])
        verdict[:] = [sure] if sure is not None else []
        return sure is not None

    try:
        if wait_until(_probe, timeout) and not verdict:
            passed(f'{parent} → {child}' + (f': translation {_vec(translation)}'
                                            if translation else ' is in the tree')
                   + (f', yaw {yaw:.3f}' if yaw is not None else ''))
            return
        if terminal is not None and terminal.ended() and not verdict:
            lines = [ln for ln in terminal.lines if ln.strip()]
            raise CheckError(what, f'`{command}` ended' + (f': {lines[-1].strip()!r}'
                                                          if lines else ', printing nothing'),
                             'read its last line: it names what went wrong', lines[-4:],
                             'What it printed last:')
        wrong = verdict[0] if verdict else _frame_names(tree, parent, child, timeout)
        if wrong is None and failures and recent:
            wrong = _stale(tree, child, failures[0])
        if wrong is not None:
            raise CheckError(what, *wrong)
        if failures:
            err = failures[0]
            raise CheckError(what, f'the lookup raised {_raised(err)}',
                             getattr(err, 'try_hint', '') or 'read the error: it names the '
                                                            'frame and the time it could not '
                                                            'find')
        t = got[0]
        v, q = t.transform.translation, t.transform.rotation
        seen = f'it is at {_vec((v.x, v.y, v.z))}, yaw {_yaw((q.x, q.y, q.z, q.w)):.3f}'
        raise CheckError(what, seen, hint or 'compare each field you set with the values '
                                             'asked for')
    finally:
        tree.close()
        if terminal is not None:
            terminal.stop()


@judged
def echo_prints(command: str, seconds: float = 10.0, cwd: str | Path | None = None) -> None:
    """`command` (a `ros2 run tf2_ros tf2_echo SOURCE TARGET` line) prints a transform within
    `seconds`; when it only waits, its own last line names the frame it cannot find."""
    from robot_lab.grading.check.output import command_prints

    try:
        command_prints(command, r'^- Translation: \[', seconds=seconds, cwd=cwd)
    except CheckError as err:
        if 'Invalid frame ID' not in err.seen and 'Invalid argument' not in err.seen:
            raise
        raise CheckError(err.expected, err.seen,
                         'use the frame names as view_frames shows them (world, turtle1, '
                         'turtle2): exact, with no leading /', err.details, err.title) from None


@judged
def follows(follower: str = 'turtle2', leader: str = 'turtle1',
            offset: tuple[float, float] = (0.0, 0.0), near: float = 1.0, timeout: float = 30.0,
            target: str | None = None, hint: str | None = None) -> None:
    """`follower` (a turtlesim turtle) drives to within `near` m of `leader`'s position (plus
    `offset`, in the leader's frame: the carrot), read from their /pose topics, not from TF."""
    from turtlesim.msg import Pose

    from robot_lab.rclpy_session import session

    name = target or leader
    what = f'{follower} to drive to within {near:g} m of {name}'
    poses: dict[str, Any] = {}
    first: list[float] = []
    sess = session()
    node = sess.hidden_node(f'check_follow_{next(_COUNT)}')

    def _keep(turtle: str) -> Callable[[Any], None]:
        def keep(msg: Any) -> None:
            poses[turtle] = msg
        return keep

    for turtle in (leader, follower):
        node.create_subscription(Pose, f'/{turtle}/pose', _keep(turtle), 10)
    sess.add_node(node)

    def _distance() -> float | None:
        lead, follow = poses.get(leader), poses.get(follower)
        if lead is None or follow is None:
            return None
        dx, dy = offset
        c, s = math.cos(lead.theta), math.sin(lead.theta)
        x, y = lead.x + c * dx - s * dy, lead.y + s * dx + c * dy
        return math.hypot(x - follow.x, y - follow.y)

    def _probe() -> bool:
        d = _distance()
        if d is not None and not first:
            first.append(d)
        last[:] = [d]
        # near: done; 1.5 m further than at the start: it steers away, and will go on
        return d is not None and (d < near or d > first[0] + 1.5)

    last: list[float | None] = [None]
    try:
        if wait_until(_probe, timeout) and (last[0] is not None and last[0] < near):
            passed(f'{follower} drives to within {near:g} m of {name}')
            return
        if leader not in poses:
            raise CheckError(what, f'no pose on /{leader}/pose', 'is turtlesim running? '
                             'Run the cell that launches the demo again')
        if follower not in poses:
            raise CheckError(what, f'no pose on /{follower}/pose: {follower} was never '
                             'spawned', "your listener spawns it: read the launch's log "
                             '(demo.logs()) for the error that stopped it')
        d = last[0]
        assert d is not None
        start = first[0] if first else d
        follow = poses[follower]
        if d > start + 0.2:
            seen = f'{follower} drove away, from {start:.1f} m to {d:.1f} m'
        elif abs(d - start) <= 0.2:
            seen = (f'{follower} stayed {d:.1f} m away, at ({follow.x:.2f}, {follow.y:.2f})')
        else:
            seen = f'{follower} came from {start:.1f} m to {d:.1f} m only, in {timeout:g} s'
        raise CheckError(what, seen, hint or 'look up where the target is seen from '
                                             f'{follower} and steer towards it')
    finally:
        sess.remove_node(node)
        node.destroy_node()


def _student_call(fn: Callable[..., Any], what: str, *args: Any) -> Any:
    """Call the student's function; their error (a tf2 one with its advice) is the check's."""
    try:
        return fn(*args)
    except Exception as err:
        if isinstance(err, NotImplementedError):
            hint = 'replace the placeholder in your answer cell with your code'
        else:
            hint = getattr(err, 'try_hint', '') or 'run it in the answer cell and read the ' \
                                                  'error line'
        raise CheckError(what, f'it raised {_raised(err)}', hint,
                         student_frames(err, outside_the_kit)) from None


def _stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _frames_of(t: Any, what: str, target: str, source: str) -> None:
    frames = (getattr(getattr(t, 'header', None), 'frame_id', None),
              getattr(t, 'child_frame_id', None))
    if frames == (source, target):
        raise CheckError(what, f'it returned {target} seen from {source} (header.frame_id '
                         f'{source!r}, child_frame_id {target!r})',
                         'lookup_transform(target_frame, source_frame, time): the first frame '
                         'is the one you look from')
    if frames != (target, source):
        raise CheckError(what, f'it returned {t!r:.120}', f'return what lookup_transform('
                         f'{target!r}, {source!r}, …) returns: a TransformStamped')


@judged
def lookup_returns(fn: Callable[[Any], Any], target: str, source: str) -> None:
    """`fn(buffer)`, called as soon as a listener starts filling `buffer`, returns `source`
    seen from `target` (a TransformStamped), as the buffer has it at the stamp returned."""
    import rclpy
    from rclpy.duration import Duration

    what = f'{getattr(fn, "__name__", "your function")}(buffer) to return {source} seen from ' \
           f'{target}, called as the listener starts'
    tree = _Tree()
    try:
        t = _student_call(fn, what, tree.buffer)
        _frames_of(t, what, target, source)
        stamp = rclpy.time.Time(nanoseconds=_stamp_ns(t.header.stamp))
        want = tree.buffer.lookup_transform(target, source, stamp, Duration(seconds=1.0))
        a, b = t.transform.translation, want.transform.translation
        if math.dist((a.x, a.y, a.z), (b.x, b.y, b.z)) > 1e-6:
            raise CheckError(what, f'it returned {_vec((a.x, a.y, a.z))}, the buffer has '
                             f'{_vec((b.x, b.y, b.z))} at that stamp',
                             'return the lookup itself, unchanged')
    finally:
        tree.close()
    passed(f'{what[:what.index(" to return")]} returns {source} seen from {target}, '
           'right after the listener starts')


@judged
def time_travel(fn: Callable[[Any, Any], Any], seconds: float = 5.0,
                driver: str = 'turtle1', follower: str = 'turtle2', fixed: str = 'world',
                timeout: float = 20.0) -> None:
    """`fn(buffer, now)` returns where `driver` was `seconds` ago, seen from where
    `follower` is at `now` (lookup_transform_full through `fixed`). The check drives
    `driver` round a circle so that then and now differ, and waits until the buffer holds
    `seconds` of history."""
    import rclpy
    from geometry_msgs.msg import Twist

    what = (f'{getattr(fn, "__name__", "your function")}(buffer, now) to return {driver} '
            f'{seconds:g} s ago, seen from {follower} now')
    tree = _Tree()
    drive = tree.node.create_publisher(Twist, f'/{driver}/cmd_vel', 10)
    stop = threading.Event()

    def _drive() -> None:
        while not stop.is_set():
            msg = Twist()
            msg.linear.x, msg.angular.z = 1.5, 1.0
            drive.publish(msg)
            stop.wait(0.1)

    feeder = threading.Thread(target=_drive, name='robot_lab-check-drive', daemon=True)
    feeder.start()
    clock_type = tree.node.get_clock().clock_type

    def _time(ns: int) -> Any:
        return rclpy.time.Time(nanoseconds=ns, clock_type=clock_type)

    def _at(ns: int) -> Any:
        """(now, expected, same time in the past, both now) once history is long enough."""
        now, then = _time(ns), _time(ns - int(seconds * 1e9))
        try:
            return (now, tree.buffer.lookup_transform_full(follower, now, driver, then, fixed),
                    tree.buffer.lookup_transform(follower, driver, then),
                    tree.buffer.lookup_transform(follower, driver, now))
        except Exception:  # not yet seconds of history: wait on
            return None

    def _probe() -> Any:
        lead, follow = tree.edge(driver), tree.edge(follower)
        if lead is None or follow is None:
            return None
        found = _at(min(lead.stamp_ns, follow.stamp_ns))
        if found is None:
            return None
        pos = [(t.transform.translation.x, t.transform.translation.y) for t in found[1:]]
        # then and now must differ, or a lookup of the wrong times would pass
        return found if min(math.dist(pos[0], pos[1]), math.dist(pos[0], pos[2])) > 0.2 \
            else None

    try:
        found = wait_until(_probe, timeout)
        if not found:
            raise CheckError(f'{seconds:g} s of moving {driver} and {follower} in the buffer',
                             f'after {timeout:g} s there is not (frames: '
                             f'{", ".join(sorted(e.child for e in tree.all_edges())) or "none"})',
                             'is the demo running? Run the cell that launches it again')
        now, want, past, present = found
        t = _student_call(fn, what, tree.buffer, now)
        _frames_of(t, what, follower, driver)
        got = (t.transform.translation.x, t.transform.translation.y)

        def _near(other: Any) -> bool:
            return math.dist(got, (other.transform.translation.x,
                                   other.transform.translation.y)) < 1e-4

        if _near(want):
            passed(f'{getattr(fn, "__name__", "your function")}(buffer, now) returns {driver} '
                   f'{seconds:g} s ago, seen from {follower} now')
            return
        if _near(past):
            raise CheckError(what, f'it returned {driver} seen from where {follower} was '
                             f'{seconds:g} s ago (both frames in the past)',
                             'lookup_transform_full: target_time=now for '
                             f'{follower}, source_time=now - {seconds:g} s for {driver}, '
                             f"fixed_frame='{fixed}'")
        if _near(present):
            raise CheckError(what, f'it returned {driver} now, not {seconds:g} s ago',
                             f'source_time is now - Duration(seconds={seconds:g})')
        raise CheckError(what, f'it returned {_vec(got)}; {driver} {seconds:g} s ago is at '
                         f'{_vec((want.transform.translation.x, want.transform.translation.y))}'
                         f' seen from {follower}',
                         f'the past time is now - Duration(seconds={seconds:g})')
    finally:
        stop.set()
        feeder.join(timeout=2.0)
        tree.close()
