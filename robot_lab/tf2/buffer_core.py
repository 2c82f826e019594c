"""tf2's BufferCore in Python, with tf2_py's method names (tf2/src/buffer_core.cpp).

PyPI has no tf2: geometry2's core is C++ behind the extension `tf2_py`. This is the same
algorithm written anew: frames get numbers, each frame keeps its parent's transform over
time (`time_cache`), and a lookup walks from both frames up to their common parent,
composing on the way. Time 0 means the latest time common to the chain. What a student
reads — the insert errors (TF_SELF_TRANSFORM, TF_NAN_INPUT, TF_DENORMALIZED_QUATERNION,
TF_OLD_DATA) and every exception's text — is upstream's, byte for byte.
"""

from __future__ import annotations

import math
import threading
from typing import Any

from rclpy.impl.rcutils_logger import RcutilsLogger

from robot_lab.tf2 import linear_math as lm
from robot_lab.tf2.exceptions import (
    InvalidArgumentException,
    LookupException,
    TransformException,
)
from robot_lab.tf2.frame_walk import RAISE, CanTransformAccum, TransformAccum, Walker
from robot_lab.tf2.time_cache import (
    DEFAULT_CACHE_TIME,
    Cache,
    StaticCache,
    TF2Error,
    TimeCache,
    TransformStorage,
    display,
    seconds,
)

__all__ = ['QUATERNION_NORMALIZATION_TOLERANCE', 'BufferCore', 'nanoseconds_of']

# tf2's tolerance on |q|^2 - 1 (10e-3, as upstream writes it).
QUATERNION_NORMALIZATION_TOLERANCE = 10e-3
# RCUTILS_LOG_* with no name, as the C++ core logs: `[ERROR] [stamp] []: TF_...`.
_LOG = RcutilsLogger('')



def nanoseconds_of(time: Any) -> int:
    """A time as tf2_py reads it: a message (sec, nanosec) or an rclpy Time (nanoseconds)."""
    if hasattr(time, 'sec') and hasattr(time, 'nanosec'):
        return int(time.sec) * 10**9 + int(time.nanosec)
    if hasattr(time, 'nanoseconds'):
        return int(time.nanoseconds)
    raise TypeError('time must have sec and nanosec, or nanoseconds.')


def _duration_nanoseconds(duration: Any) -> int:
    if hasattr(duration, 'sec') and hasattr(duration, 'nanosec'):
        return int(duration.sec) * 10**9 + int(duration.nanosec)
    if hasattr(duration, 'nanoseconds'):
        return int(duration.nanoseconds)
    raise TypeError('duration must have sec and nanosec, or nanoseconds.')


def _stamp_message(nanoseconds: int) -> Any:
    from builtin_interfaces.msg import Time
    sec = -(-nanoseconds // 10**9) if nanoseconds < 0 else nanoseconds // 10**9
    return Time(sec=sec, nanosec=nanoseconds - sec * 10**9)


def _transform_message(target: str, source: str, stamp: int,
                       pose: tuple[lm.Vec, lm.Quat]) -> Any:
    from geometry_msgs.msg import TransformStamped
    msg = TransformStamped()
    msg.header.stamp = _stamp_message(stamp)
    msg.header.frame_id = target
    msg.child_frame_id = source
    t, q = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = pose[0]
    q.x, q.y, q.z, q.w = pose[1]
    return msg


class BufferCore(Walker):
    """tf2_py's BufferCore: set_transform(_static), lookup_transform(_full)_core,
    can_transform(_full)_core, get_latest_common_time, all_frames_as_yaml/string, clear."""

    def __init__(self, cache_time: Any = None) -> None:
        self.cache_time = (DEFAULT_CACHE_TIME if cache_time is None
                           else _duration_nanoseconds(cache_time))
        self._frame_ids: dict[str, int] = {'NO_PARENT': 0}
        self._frame_names: list[str] = ['NO_PARENT']
        self._frames: list[Cache | None] = [None]
        self._authority: dict[int, str] = {}
        self._lock = threading.RLock()

    # --- frames ---------------------------------------------------------------------------

    # the walker's view of this buffer (frame_walk.Walker)
    def frame_cache(self, number: int) -> Cache | None:
        return self._frames[number] if number < len(self._frames) else None

    def frame_name(self, number: int) -> str:
        if number >= len(self._frame_names):
            raise LookupException(f'Reverse lookup of frame id {number} failed!')
        return self._frame_names[number]

    def frame_number(self, name: str) -> int:
        return self._frame_ids.get(name, 0)

    def _number_or_insert(self, name: str) -> int:
        number = self._frame_ids.get(name)
        if number is None:
            number = len(self._frames)
            self._frames.append(None)
            self._frame_ids[name] = number
            self._frame_names.append(name)
        return number

    def _validate(self, function: str, frame_id: str) -> int:
        """validateFrameId, the throwing form (lookups)."""
        if not frame_id:
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {function} - in tf2 frame_ids '
                'cannot be empty')
        if frame_id.startswith('/'):
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {function} - in tf2 frame_ids '
                "cannot start with a '/'")
        number = self.frame_number(frame_id)
        if number == 0:
            raise LookupException(f'"{frame_id}" passed to {function} does not exist. ')
        return number

    def _validate_quietly(self, function: str, frame_id: str) -> tuple[int, str]:
        """validateFrameId, the form that fills an error message (can_transform)."""
        if not frame_id:
            why = 'in tf2 frame_ids cannot be empty'
        elif frame_id.startswith('/'):
            why = "in tf2 frame_ids cannot start with a '/'"
        else:
            number = self.frame_number(frame_id)
            if number:
                return number, ''
            why = 'frame does not exist'
        return 0, f'Invalid frame ID "{frame_id}" passed to {function} - {why}'

    # --- insert ---------------------------------------------------------------------------

    def set_transform(self, transform: Any, authority: str) -> None:
        self._set(transform, authority, is_static=False)

    def set_transform_static(self, transform: Any, authority: str) -> None:
        self._set(transform, authority, is_static=True)

    def _set(self, transform: Any, authority: str, is_static: bool) -> bool:
        stamp = nanoseconds_of(transform.header.stamp)
        t, r = transform.transform.translation, transform.transform.rotation
        origin = (float(t.x), float(t.y), float(t.z))
        rotation = lm.stored_rotation((float(r.x), float(r.y), float(r.z), float(r.w)))
        return self.set_transform_impl(origin, rotation, transform.header.frame_id,
                                       transform.child_frame_id, stamp, authority, is_static)

    def set_transform_impl(self, origin: lm.Vec, rotation: lm.Quat, frame_id: str,
                           child_frame_id: str, stamp: int, authority: str,
                           is_static: bool) -> bool:
        """setTransformImpl: refuse a bad sample with upstream's error, else store it."""
        parent = frame_id[1:] if frame_id.startswith('/') else frame_id
        child = child_frame_id[1:] if child_frame_id.startswith('/') else child_frame_id
        bad = False
        if child == parent:
            _LOG.error(f'TF_SELF_TRANSFORM: Ignoring transform from authority "{authority}" '
                       f'with frame_id and  child_frame_id "{child}" because they are the same')
            bad = True
        if not child:
            _LOG.error(f'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "{authority}" '
                       'because child_frame_id not set ')
            bad = True
        if not parent:
            _LOG.error(f'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "{child}"  '
                       f'from authority "{authority}" because frame_id not set')
            bad = True
        if any(math.isnan(v) for v in (*origin, *rotation)):
            _LOG.error(
                f'TF_NAN_INPUT: Ignoring transform for child_frame_id "{child}" from authority '
                f'"{authority}" because of a nan value in the transform '
                '(%f %f %f) (%f %f %f %f)' % (*origin, *rotation))
            bad = True
        x, y, z, w = rotation
        if not abs((w * w + x * x + y * y + z * z) - 1.0) < QUATERNION_NORMALIZATION_TOLERANCE:
            _LOG.error(
                f'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "{child}" '
                f'from authority "{authority}" because of an invalid quaternion in the '
                'transform (%f %f %f %f)' % rotation)
            bad = True
        if bad:
            return False
        with self._lock:
            number = self._number_or_insert(child)
            cache = self.frame_cache(number)
            if cache is None or cache.is_static != is_static:
                cache = StaticCache() if is_static else TimeCache(self.cache_time)
                self._frames[number] = cache
            sample = TransformStorage(stamp, rotation, origin,
                                      self._number_or_insert(parent), number)
            if not cache.insert(sample):
                _LOG.warning(
                    f'TF_OLD_DATA ignoring data from the past for frame {child} at time '
                    f'{display(stamp)} according to authority {authority}\nPossible reasons '
                    'are listed at http://wiki.ros.org/tf/Errors%20explained')
                return False
            self._authority[number] = authority
        return True

    def clear(self) -> None:
        with self._lock:
            for cache in self._frames[1:]:
                if cache is not None:
                    cache.clear()

    # --- lookups --------------------------------------------------------------------------

    def _lookup(self, target: str, source: str, time: int) -> tuple[tuple[lm.Vec, lm.Quat], int]:
        """lookupTransformImpl: the transform and the time it was taken at."""
        with self._lock:
            if target == source:
                stamp = time
                if time == 0:
                    cache = self.frame_cache(self.frame_number(target))
                    stamp = cache.latest_stamp() if cache is not None else time
                return (lm.ZERO, lm.IDENTITY), stamp
            target_id = self._validate('lookupTransform argument target_frame', target)
            source_id = self._validate('lookupTransform argument source_frame', source)
            accum = TransformAccum()
            code, text = self.walk_to_top_parent(accum, time, target_id, source_id)
            if code != TF2Error.NO_ERROR:
                raise RAISE.get(code, TransformException)(text)
            return (accum.result_vec, accum.result_quat), accum.time

    def _lookup_full(self, target: str, target_time: int, source: str, source_time: int,
                     fixed: str) -> tuple[tuple[lm.Vec, lm.Quat], int]:
        with self._lock:
            self._validate('lookupTransform argument target_frame', target)
            self._validate('lookupTransform argument source_frame', source)
            self._validate('lookupTransform argument fixed_frame', fixed)
            tf1, _ = self._lookup(fixed, source, source_time)
            tf2, stamp = self._lookup(target, fixed, target_time)
            return lm.compose(tf2, tf1), stamp

    def lookup_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Any:
        pose, stamp = self._lookup(target_frame, source_frame, nanoseconds_of(time))
        return _transform_message(target_frame, source_frame, stamp, pose)

    def lookup_transform_full_core(self, target_frame: str, target_time: Any,
                                   source_frame: str, source_time: Any,
                                   fixed_frame: str) -> Any:
        pose, stamp = self._lookup_full(target_frame, nanoseconds_of(target_time), source_frame,
                                        nanoseconds_of(source_time), fixed_frame)
        return _transform_message(target_frame, source_frame, stamp, pose)

    def _can(self, target_id: int, source_id: int, time: int) -> tuple[bool, str]:
        """canTransformInternal."""
        with self._lock:
            if target_id == 0 or source_id == 0:
                return False, 'Source or target frame is not yet defined'
            if target_id == source_id:
                return True, ''
            code, text = self.walk_to_top_parent(CanTransformAccum(), time, target_id,
                                                 source_id)
            return code == TF2Error.NO_ERROR, text

    def can_transform_core(self, target_frame: str, source_frame: str,
                           time: Any) -> tuple[int, str]:
        """(1, '') or (0, why), as tf2_py returns it."""
        stamp = nanoseconds_of(time)
        if target_frame == source_frame:
            return 1, ''
        with self._lock:
            target_id, text = self._validate_quietly('canTransform argument target_frame',
                                                     target_frame)
            if not target_id:
                return 0, text
            source_id, text = self._validate_quietly('canTransform argument source_frame',
                                                     source_frame)
            if not source_id:
                return 0, text
            ok, text = self._can(target_id, source_id, stamp)
        return int(ok), text

    def can_transform_full_core(self, target_frame: str, target_time: Any, source_frame: str,
                                source_time: Any, fixed_frame: str) -> tuple[int, str]:
        target_ns, source_ns = nanoseconds_of(target_time), nanoseconds_of(source_time)
        with self._lock:
            ids = []
            for function, frame in (('canTransform argument target_frame', target_frame),
                                    ('canTransform argument source_frame', source_frame),
                                    ('canTransform argument fixed_frame', fixed_frame)):
                number, text = self._validate_quietly(function, frame)
                if not number:
                    return 0, text
                ids.append(number)
            target_id, source_id, fixed_id = ids
            ok, text = self._can(target_id, fixed_id, target_ns)
            if ok:
                ok, text = self._can(fixed_id, source_id, source_ns)
        return int(ok), text

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Any:
        from rclpy.time import Time
        with self._lock:
            target_id = self._validate('get_latest_common_time', target_frame)
            source_id = self._validate('get_latest_common_time', source_frame)
            code, stamp, text = self.latest_common_time(target_id, source_id)
        if code != TF2Error.NO_ERROR:
            raise TransformException(text)
        sec = stamp // 10**9
        return Time(seconds=sec, nanoseconds=stamp - sec * 10**9)

    # --- introspection --------------------------------------------------------------------

    def all_frames_as_string(self) -> str:
        with self._lock:
            return self.frames_as_string()

    def all_frames_as_yaml(self, current_time: int = 0) -> str:
        """allFramesAsYAML: each frame's parent, broadcaster, rate and stamps."""
        with self._lock:
            lines: list[str] = []
            if len(self._frames) == 1:
                return '[]'
            for number in range(1, len(self._frames)):
                cache = self.frame_cache(number)
                latest = cache.get_data(0) if cache is not None else None
                if cache is None or latest is None:
                    continue
                newest, oldest = cache.latest_stamp(), cache.oldest_stamp()
                rate = len(cache) * 1e9 / max(newest - oldest, 100_000)
                lines += [f'{self._frame_names[number]}: ',
                          f"  parent: '{self._frame_names[latest.frame_id]}'",
                          f"  broadcaster: '{self.authority(self._frame_names[number])}'",
                          f'  rate: {rate:.3f}',
                          f'  most_recent_transform: {display(newest)}',
                          f'  oldest_transform: {display(oldest)}']
                if current_time:
                    lines.append(f'  transform_delay: {seconds(current_time - newest):.3f}')
                lines.append(f'  buffer_length: {seconds(newest - oldest):.3f}')
            return ''.join(line + '\n' for line in lines)

    def _frameExists(self, frame_id: str) -> bool:  # noqa: N802 (tf2_py's name)
        with self._lock:
            return frame_id in self._frame_ids

    def _getFrameStrings(self) -> list[str]:  # noqa: N802 (tf2_py's name)
        with self._lock:
            return list(self._frame_names[1:])

    def _allFramesAsDot(self, time: Any = None) -> str:  # noqa: N802 (tf2_py's name)
        from robot_lab.tf2.introspection import frames_as_dot
        with self._lock:
            return frames_as_dot(self, 0 if time is None else nanoseconds_of(time))

    def _chain(self, target_frame: str, target_time: Any, source_frame: str,
               source_time: Any, fixed_frame: str) -> list[str]:
        with self._lock:
            return self.chain_as_vector(target_frame, nanoseconds_of(target_time),
                                        source_frame, nanoseconds_of(source_time),
                                        fixed_frame)

    def frames(self) -> list[tuple[str, Cache | None]]:
        """(name, cache) of every frame known, in the order they were first seen."""
        return [(self._frame_names[n], self.frame_cache(n)) for n in range(1, len(self._frames))]

    def authority(self, name: str) -> str:
        return self._authority.get(self.frame_number(name), 'no recorded authority')

    def parent_name(self, number: int) -> str:
        return self._frame_names[number]

    # --- velocity -------------------------------------------------------------------------

    def lookupVelocityCore(self, tracking_frame: str, observation_frame: str,  # noqa: N802
                           time: Any, averaging_interval: Any) -> tuple[lm.Vec, lm.Vec]:
        return self.lookupVelocityFullCore(tracking_frame, observation_frame, observation_frame,
                                           (0.0, 0.0, 0.0), tracking_frame, time,
                                           averaging_interval)

    def lookupVelocityFullCore(  # noqa: N802 (tf2_py's name)
            self, tracking_frame: str, observation_frame: str, reference_frame: str,
            reference_point: tuple[float, float, float], reference_point_frame: str,
            time: Any, averaging_interval: Any) -> tuple[lm.Vec, lm.Vec]:
        from robot_lab.tf2.velocity import lookup_velocity
        return lookup_velocity(self, tracking_frame, observation_frame, reference_frame,
                               reference_point, reference_point_frame, nanoseconds_of(time),
                               _duration_nanoseconds(averaging_interval))
