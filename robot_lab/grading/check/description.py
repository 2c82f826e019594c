"""Checks of a robot description and its TF tree (lesson 12): the URDF's links and joints,
its xacro twin, a broadcaster's transforms on /tf, a listener's point in another frame.

Each names the one mistake a student makes there: a joint on the wrong parent link, a
revolute joint without limits (urdfdom's refusal, with its line), a quaternion that is not
unit length, a stamp from the past, a lookup before the transform exists.
"""

from __future__ import annotations

import itertools
import math
import shutil
import subprocess
import time
import traceback
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from robot_lab.errors import RobotLabError, UrdfError
from robot_lab.grading.check.base import (
    CheckError,
    callback_failed,
    judged,
    outside_the_kit,
    passed,
    student_frames,
)
from robot_lab.tf2.linear_math import euler_from_quaternion

__all__ = ['point_in_frame', 'transform_broadcast', 'translation_is', 'urdf_tree',
           'xacro_expands']


def _robot(text: str, source: str, what: str) -> Any:
    """The parsed robot, or the CheckError that says where urdfdom would refuse it."""
    from robot_lab.urdf.model import parse_urdf

    try:
        return parse_urdf(text, source)
    except UrdfError as err:
        where = f'line {err.line}: ' if err.line else ''
        raise CheckError(what, f'check_urdf refuses it: {where}{err.message}',
                         err.fix or 'run check_urdf on the file and fix the line it names'
                         ) from None


def _tree_errors(robot: Any, parents: Mapping[str, str],
                 joint_types: Mapping[str, str]) -> tuple[str, str] | None:
    """(what is seen, what to try) for the first way `robot` differs; None if it doesn't."""
    from robot_lab.urdf.compare import differences

    found = differences(robot, parents=parents, joint_types=joint_types)
    if not found:
        return None
    first = found[0]
    name, wanted, joint = first.name, first.wanted, first.joint
    if first.kind == 'no_link':
        return (f'no link {name!r} (links: {", ".join(robot.links)})',
                f'add <link name="{name}"> and a joint that joins it to {wanted}')
    if first.kind == 'parent' and joint is None:
        return (f'{name!r} is the root: no joint has it as its child',
                f'add a joint with <parent link="{wanted}"/> <child link="{name}"/>')
    if first.kind == 'parent' and joint is not None:
        return (f"{name}'s parent link is {joint.parent!r} (joint {joint.name!r}, "
                f'line {joint.line})',
                f'in joint {joint.name!r}, write <parent link="{wanted}"/>: the parent '
                'is the link it is fixed to, the child the one it carries')
    if first.kind == 'no_joint':
        return (f'no joint {name!r} (joints: {", ".join(robot.joints) or "none"})',
                f'name the joint {name!r}')
    assert joint is not None  # joint_type: the joint is there, of another type
    why = (' (a wheel turns without end: continuous needs no limits)'
           if wanted == 'continuous' else '')
    return (f'joint {name!r} is {joint.type} (line {joint.line})',
            f'make it type="{wanted}"{why}')


@judged
def urdf_tree(path: str | Path, parents: Mapping[str, str],
              joint_types: Mapping[str, str] = {}) -> None:
    """The URDF parses as check_urdf parses it, each link in `parents` hangs from its parent
    link, and each joint in `joint_types` has that type."""
    file = Path(path)
    what = f'{file.name} to describe the robot'
    if not file.is_file():
        raise CheckError(what, f'there is no {file.name} yet',
                         'run your answer cell above: it writes the file')
    robot = _robot(file.read_text(), file.name, what)
    wrong = _tree_errors(robot, parents, joint_types)
    if wrong:
        raise CheckError(what, *wrong)
    moving = [n for n, k in joint_types.items() if k != 'fixed']
    passed(f'{file.name}: {robot.root} carries {", ".join(parents)}'
           + (f'; {", ".join(moving)} turn' if moving else ''))


def _expand(xacro_file: Path, what: str) -> str:
    program = shutil.which('xacro')
    if program is None:
        raise CheckError(what, 'no xacro program on PATH',
                         'run the notebook from its first cell (it puts the venv on PATH)')
    try:
        done = subprocess.run([program, str(xacro_file)], capture_output=True, text=True,
                              timeout=60, check=False)
    except subprocess.TimeoutExpired:
        raise CheckError(what, 'xacro ran for 60 s without finishing',
                         'look for a macro that calls itself') from None
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines() or ['no message']  # error first, then where
        first = lines[0].removeprefix('error: ').strip()
        raise CheckError(what, f'xacro failed: {first}',
                         'fix what xacro names (run !xacro FILE to see all of it)')
    return done.stdout


def _joint_key(joint: Any) -> tuple[Any, ...]:
    return (joint.type, joint.parent, joint.child,
            tuple(round(v, 6) for v in (*joint.xyz, *joint.rpy, *joint.axis)))


@judged
def xacro_expands(xacro_path: str | Path, like: str | Path, macro: str, calls: int = 2) -> None:
    """The xacro file defines `macro`, calls it `calls` times, and expands to the robot of
    the URDF `like`: the same links and the same joints (type, links, origin, axis)."""
    file, urdf = Path(xacro_path), Path(like)
    what = f'{file.name} to expand to the robot of {urdf.name}'
    if not file.is_file():
        raise CheckError(what, f'there is no {file.name} yet',
                         'run your answer cell above: it writes the file')
    text = file.read_text()
    if f'name="{macro}"' not in text or '<xacro:macro' not in text:
        raise CheckError(what, f'no <xacro:macro name="{macro}"> in {file.name}',
                         f'define the macro once: <xacro:macro name="{macro}" params="...">')
    used = text.count(f'<xacro:{macro} ') + text.count(f'<xacro:{macro}/')
    if used < calls:
        raise CheckError(what, f'the macro is called {used} time(s)',
                         f'call it once per wheel: <xacro:{macro} .../> {calls} times')
    robot = _robot(_expand(file, what), f'{file.name} (expanded)', what)
    model = _robot(urdf.read_text(), urdf.name, f'{urdf.name} to be a valid URDF')
    missing = [n for n in model.links if n not in robot.links]
    extra = [n for n in robot.links if n not in model.links]
    if missing or extra:
        seen = '; '.join(part for part in (f'missing links {", ".join(missing)}' if missing
                                           else '', f'extra links {", ".join(extra)}'
                                           if extra else '') if part)
        raise CheckError(what, seen, 'compare !xacro FILE with the URDF: a macro parameter '
                         'misspelt in ${...} or a link left out')
    for name, joint in model.joints.items():
        twin = robot.joints.get(name)
        if twin is None:
            raise CheckError(what, f'no joint {name!r} in the expansion',
                             'name the joints as in the URDF, e.g. ${side}_wheel_joint')
        if _joint_key(twin) != _joint_key(joint):
            raise CheckError(what, f'joint {name!r} differs from {urdf.name}: {twin.type} '
                             f'{twin.parent}→{twin.child} at xyz {twin.xyz} axis {twin.axis}',
                             'pass each wheel its own side and y; keep the origin and axis '
                             'of the URDF')
    passed(f'{file.name} expands to {len(robot.links)} links and {len(robot.joints)} joints, '
           f'as {urdf.name}; the {macro} macro used {used} times')


def _stamp_seconds(stamp: Any) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi


def _yaw(q: Any) -> float:
    """The heading of a rotation (geometry_msgs Quaternion): the yaw tf2_echo prints, so
    a base tilted by roll and pitch (a slope) still faces where its x axis points; the
    planar 2·atan2(z, w) holds only when both are zero."""
    return euler_from_quaternion((q.x, q.y, q.z, q.w))[2]


def _heading_error(samples: list[tuple[float, float, float]]) -> float | None:
    """The largest angle between the yaw a transform says and the way the frame moved.

    Along an arc the chord points at the mean of its two headings, so messages a busy
    kernel skipped (a longer chord) do not count as an error."""
    worst: float | None = None
    for (x0, y0, yaw0), (x1, y1, yaw1) in itertools.pairwise(samples):
        if math.hypot(x1 - x0, y1 - y0) < 1e-3:
            continue
        moved = math.atan2(y1 - y0, x1 - x0)
        off = abs(_wrap(yaw0 + _wrap(yaw1 - yaw0) / 2 - moved))
        worst = off if worst is None else max(worst, off)
    return worst


@judged
def transform_broadcast(parent: str, child: str, timeout: float = 5.0,
                        moves_forward: bool = True) -> None:
    """/tf carries `parent` → `child` with unit quaternions stamped now; with
    `moves_forward`, the frame faces the way it moves (x forward, as a robot base drives)."""
    from rclpy.clock import Clock

    from robot_lab.graph.topics import echo_stream

    what = f'/tf to carry {parent} → {child}, stamped now'
    clock = Clock()
    seen_pairs: set[str] = set()
    samples: list[tuple[float, float, float]] = []
    stamps: set[float] = set()
    start = time.monotonic()
    stop = start + timeout
    try:
        stream = echo_stream('/tf', 'tf2_msgs/msg/TFMessage', timeout=timeout)
        try:
            for msg in stream:
                now = clock.now().nanoseconds * 1e-9
                for t in msg.transforms:
                    seen_pairs.add(f'{t.header.frame_id} → {t.child_frame_id}')
                    if (t.header.frame_id, t.child_frame_id) != (parent, child):
                        continue
                    q = t.transform.rotation
                    norm2 = q.x ** 2 + q.y ** 2 + q.z ** 2 + q.w ** 2
                    if abs(norm2 - 1.0) > 10e-6:  # tf2's own test for a denormalized one
                        norm = math.sqrt(norm2)
                        raise CheckError(
                            what, f'rotation (x, y, z, w) = ({q.x:g}, {q.y:g}, {q.z:g}, '
                            f'{q.w:g}), length {norm:.6g}: tf2 refuses it '
                            '(TF_DENORMALIZED_QUATERNION)',
                            'a rotation by yaw about z is x = y = 0, z = sin(yaw / 2), '
                            'w = cos(yaw / 2): set w too (it starts at 1)')
                    stamp = _stamp_seconds(t.header.stamp)
                    stamps.add(stamp)
                    age = now - stamp
                    # A loaded machine delivers late, never 5 s late; a stale stamp is older.
                    if age > 5.0 or age < -1.0:
                        when = f'{age:.1f} s old' if age > 0 else f'{-age:.1f} s ahead'
                        raise CheckError(
                            what, f'a stamp {when} (header.stamp {t.header.stamp.sec}.'
                            f'{t.header.stamp.nanosec:09d}): listeners drop it (TF_OLD_DATA) or '
                            'wait for it', 'stamp each transform as you send it: '
                            't.header.stamp = self.get_clock().now().to_msg()')
                    samples.append((t.transform.translation.x, t.transform.translation.y,
                                    _yaw(q)))
                # long enough for a heading built from the whole angle to show (0.5 rad/s)
                if (len(samples) >= 10 and time.monotonic() > start + 1.5) \
                        or time.monotonic() > stop:
                    break
        finally:
            getattr(stream, 'close', lambda: None)()
    except RobotLabError:
        pass  # nobody publishes /tf: said below
    callback_failed(what)
    if not samples:
        others = ', '.join(sorted(seen_pairs)) or 'no transforms at all'
        raise CheckError(what, f'within {timeout:g} s /tf carried {others}',
                         f'is the broadcaster running, sending header.frame_id {parent!r} and '
                         f'child_frame_id {child!r}?')
    if len(samples) > 2 and len(stamps) == 1:
        raise CheckError(what, f'every transform carries the same stamp ({stamps.pop():.3f} s): '
                         'listeners keep the first and drop the rest (TF_OLD_DATA)',
                         'stamp each transform as you send it: '
                         't.header.stamp = self.get_clock().now().to_msg()')
    off = _heading_error(samples) if moves_forward else None
    if off is not None and off > 0.2:
        raise CheckError(what, f'{child} faces {math.degrees(off):.0f}° away from the way it '
                         'moves', 'set the rotation from the heading, with half the angle: '
                         'z = sin(yaw / 2), w = cos(yaw / 2) (left alone it stays (0, 0, 0, 1): '
                         'no turn)')
    passed(f'/tf carries {parent} → {child}: unit quaternions, stamped now'
           + (', facing the way it drives' if moves_forward else ''))


def _transform_failure(what: str) -> None:
    """A CheckError for a tf2 exception a callback of the student's node raised, if any."""
    from robot_lab.rclpy_session import session

    errors = session().callback_errors
    for err in list(errors):
        if err is None or not hasattr(err, 'try_hint'):
            continue
        mine = [f for f in traceback.extract_tb(err.__traceback__)
                if outside_the_kit(f.filename)]
        if not mine:
            continue
        errors.clear()
        text = f'{type(err).__name__}: {err}'
        hint = ('the transform is not there the moment your node starts: catch '
                'tf2_ros.TransformException around the lookup and skip this reading, as the '
                "tutorial's listener does (in a node of your own executor, timeout= can wait)")
        if 'past' in str(err):
            hint = 'ask for rclpy.time.Time() (the latest common time), not an old stamp'
        elif 'future' in str(err):
            hint = ('ask for rclpy.time.Time() (the latest), or give the lookup a timeout= '
                    'to wait for data that new')
        raise CheckError(what, f'your callback {mine[-1].name}() raised {text} at '
                         f'{Path(mine[-1].filename).name} line {mine[-1].lineno}', hint,
                         student_frames(err, outside_the_kit))


@judged
def point_in_frame(topic: str, frame: str, source_frame: str, timeout: float = 10.0,
                   tolerance: float = 0.02) -> None:
    """`topic` carries PointStamped in `frame` at the origin of `source_frame`, as tf2
    itself places it at the message's stamp."""
    from rclpy.duration import Duration
    from rclpy.time import Time

    from robot_lab.graph.topics import echo_stream
    from robot_lab.tf2.listener import tf_buffer

    name = '/' + topic.lstrip('/')
    what = f'{name} to carry the origin of {source_frame} in {frame}'
    buffer = tf_buffer()
    last = ''
    wrong = 0
    try:
        stream = echo_stream(name, 'geometry_msgs/msg/PointStamped', timeout=timeout)
        try:
            for msg in stream:
                if msg.header.frame_id != frame:
                    raise CheckError(what, f'header.frame_id {msg.header.frame_id!r}',
                                     f"the point is in {frame}: header.frame_id = '{frame}'")
                try:
                    t = buffer.lookup_transform(frame, source_frame, Time.from_msg(
                        msg.header.stamp), timeout=Duration(seconds=1.0))
                except Exception as err:  # tf2's own errors: the stamp is the fault
                    last = f'a stamp tf2 cannot place ({type(err).__name__})'
                    continue
                want = t.transform.translation
                got = msg.point
                off = math.dist((want.x, want.y, want.z), (got.x, got.y, got.z))
                if off <= tolerance:
                    passed(f'{name} carries {source_frame} in {frame}, as tf2 places it')
                    return
                last = (f'({got.x:.3f}, {got.y:.3f}, {got.z:.3f}); tf2 puts {source_frame} '
                        f'at ({want.x:.3f}, {want.y:.3f}, {want.z:.3f})')
                wrong += 1
                if wrong >= 5:  # five readings placed alike: the answer, not a slow start
                    break
        finally:
            getattr(stream, 'close', lambda: None)()
    except RobotLabError:
        pass
    _transform_failure(what)
    callback_failed(what)
    if last:
        raise CheckError(what, last, f"lookup_transform('{frame}', '{source_frame}', …): the "
                         'target frame comes first, and the point is its translation; stamp '
                         "the point with the transform's header.stamp")
    raise CheckError(what, f'no PointStamped within {timeout:g} s',
                     f'does your callback publish on {name} (after a successful lookup)?')


@judged
def translation_is(name: str, answer: Any, target: str, source: str,
                   tolerance: float = 0.005) -> None:
    """The student's `(x, y, z)` is where tf2 puts `source`'s origin in `target` (metres)."""
    from rclpy.duration import Duration
    from rclpy.time import Time

    from robot_lab.tf2.listener import tf_buffer

    what = f'{name} = the origin of {source} in {target}'
    if answer is None:
        raise CheckError(what, f'{name} is None: its answer cell has not set it',
                         'replace the placeholder in the answer cell, run it, then this one')
    try:
        x, y, z = (float(v) for v in answer)
    except (TypeError, ValueError):
        raise CheckError(what, f'{name} = {answer!r}',
                         'write three numbers in metres, (x, y, z)') from None
    try:
        t = tf_buffer().lookup_transform(target, source, Time(),
                                         timeout=Duration(seconds=5.0)).transform.translation
    except Exception as err:  # tf2's errors: the tree is not up
        raise CheckError(what, f'tf2 has no {target} → {source}: {err}',
                         'run the cells of section 3 again (robot_state_publisher)') from None
    if math.dist((x, y, z), (t.x, t.y, t.z)) > tolerance:
        flipped = math.dist((x, y, z), (-t.x, -t.y, -t.z)) <= tolerance
        raise CheckError(what, f'{name} = ({x:g}, {y:g}, {z:g})',
                         f'tf2_echo {target} {source}: the first frame is where you stand'
                         if flipped else f'read the Translation line of tf2_echo {target} '
                         f'{source}')
    passed(f'{name} is where tf2 puts {source} in {target}')
