"""One frame's history, as tf2's TimeCache and StaticCache keep it (tf2/src/cache.cpp).

Times are integer nanoseconds (tf2's TimePoint). A dynamic frame keeps `max_storage`
(10 s by default) of samples sorted by stamp and answers between two of them by linear
interpolation and slerp; a static frame keeps one sample and answers at any time. The
extrapolation texts are upstream's, byte for byte.
"""

from __future__ import annotations

import bisect
from enum import IntEnum
from typing import NamedTuple

from robot_lab.tf2.linear_math import Quat, Vec, lerp, slerp

DEFAULT_CACHE_TIME = 10 * 10**9  # tf2::BUFFER_CORE_DEFAULT_CACHE_TIME


class TF2Error(IntEnum):
    """tf2::TF2Error (the extrapolation kinds are ExtrapolationExceptions in Python)."""

    NO_ERROR = 0
    LOOKUP_ERROR = 1
    CONNECTIVITY_ERROR = 2
    EXTRAPOLATION_ERROR = 3
    INVALID_ARGUMENT_ERROR = 4
    TIMEOUT_ERROR = 5
    TRANSFORM_ERROR = 6
    BACKWARD_EXTRAPOLATION_ERROR = 7
    FORWARD_EXTRAPOLATION_ERROR = 8
    NO_DATA_FOR_EXTRAPOLATION_ERROR = 9


def seconds(nanoseconds: int) -> float:
    """tf2::durationToSec / timeToSec: whole seconds and the rest, scaled separately."""
    sec = -(-nanoseconds // 10**9) if nanoseconds < 0 else nanoseconds // 10**9
    return float(sec) + 1e-9 * float(nanoseconds - sec * 10**9)


def display(nanoseconds: int) -> str:
    """tf2::displayTimePoint: seconds with six decimals."""
    return f'{seconds(nanoseconds):.6f}'


class TransformStorage(NamedTuple):
    """One sample: child `child_frame_id` relative to parent `frame_id` at `stamp` (ns).
    (A tuple: built thousands of times a second, compared whole for duplicates.)"""

    stamp: int
    rotation: Quat
    translation: Vec
    frame_id: int
    child_frame_id: int


class Problem:
    """Where a failed cache read leaves its code and text (tf2's out-parameters)."""

    __slots__ = ('code', 'text')

    def __init__(self) -> None:
        self.code = TF2Error.NO_ERROR
        self.text = ''


class TimeCache:
    """A dynamic frame's samples, oldest first (upstream keeps newest first: same order
    of equal stamps, found with bisect instead of a linear walk)."""

    is_static = False

    def __init__(self, max_storage: int = DEFAULT_CACHE_TIME) -> None:
        self.max_storage = max_storage
        self._stamps: list[int] = []
        self._data: list[TransformStorage] = []

    def _find_closest(self, time: int, problem: Problem | None
                      ) -> tuple[TransformStorage, ...]:
        stamps = self._stamps
        if not stamps:
            if problem is not None:
                problem.code = TF2Error.NO_DATA_FOR_EXTRAPOLATION_ERROR
            return ()
        if time == 0:
            return (self._data[-1],)
        if len(stamps) == 1:
            if stamps[0] == time:
                return (self._data[0],)
            if problem is not None:
                problem.code = TF2Error.NO_DATA_FOR_EXTRAPOLATION_ERROR
                problem.text = (f'Lookup would require extrapolation at time {display(time)}, '
                                f'but only time {display(stamps[0])} is in the buffer')
            return ()
        latest, earliest = stamps[-1], stamps[0]
        if time == latest:
            return (self._data[-1],)
        if time == earliest:
            return (self._data[0],)
        if time > latest:
            if problem is not None:
                problem.code = TF2Error.FORWARD_EXTRAPOLATION_ERROR
                problem.text = ('Lookup would require extrapolation into the future.  '
                                f'Requested time {display(time)} but the latest data is at '
                                f'time {display(latest)}')
            return ()
        if time < earliest:
            if problem is not None:
                problem.code = TF2Error.BACKWARD_EXTRAPOLATION_ERROR
                problem.text = ('Lookup would require extrapolation into the past.  '
                                f'Requested time {display(time)} but the earliest data is at '
                                f'time {display(earliest)}')
            return ()
        older = bisect.bisect_right(stamps, time) - 1
        return (self._data[older], self._data[older + 1])

    def get_data(self, time: int, problem: Problem | None = None) -> TransformStorage | None:
        found = self._find_closest(time, problem)
        if not found:
            return None
        if len(found) == 1:
            return found[0]
        one, two = found
        if one.frame_id != two.frame_id:
            return one
        if two.stamp == one.stamp:
            return two
        ratio = (time - one.stamp) / (two.stamp - one.stamp)
        return TransformStorage(one.stamp, slerp(one.rotation, two.rotation, ratio),
                                lerp(one.translation, two.translation, ratio), one.frame_id,
                                one.child_frame_id)

    def get_parent(self, time: int, problem: Problem | None = None) -> int:
        found = self._find_closest(time, problem)
        return found[0].frame_id if found else 0

    def insert(self, data: TransformStorage) -> bool:
        """False: older than the cache keeps (TF_OLD_DATA); an exact duplicate is dropped."""
        latest = self._stamps[-1] if self._stamps else 0
        self._prune(latest)
        if self._stamps and data.stamp < latest - self.max_storage:
            return False
        at = bisect.bisect_right(self._stamps, data.stamp)
        same = at - 1
        while same >= 0 and self._stamps[same] == data.stamp:
            if self._data[same] == data:
                return True
            same -= 1
        self._stamps.insert(at, data.stamp)
        self._data.insert(at, data)
        return True

    def _prune(self, latest: int) -> None:
        cut = bisect.bisect_left(self._stamps, latest - self.max_storage)
        if cut:
            del self._stamps[:cut]
            del self._data[:cut]

    def clear(self) -> None:
        self._stamps.clear()
        self._data.clear()

    def __len__(self) -> int:
        return len(self._stamps)

    def latest_time_and_parent(self) -> tuple[int, int]:
        if not self._data:
            return 0, 0
        return self._data[-1].stamp, self._data[-1].frame_id

    def latest_stamp(self) -> int:
        return self._stamps[-1] if self._stamps else 0

    def oldest_stamp(self) -> int:
        return self._stamps[0] if self._stamps else 0


class StaticCache:
    """A static frame: its one sample, valid at every time (stamped with the time asked)."""

    is_static = True

    def __init__(self) -> None:
        self._data = TransformStorage(0, (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 0, 0)

    def get_data(self, time: int, problem: Problem | None = None) -> TransformStorage:
        data = self._data
        return TransformStorage(time, data.rotation, data.translation, data.frame_id,
                                data.child_frame_id)

    def get_parent(self, time: int, problem: Problem | None = None) -> int:
        return self._data.frame_id

    def insert(self, data: TransformStorage) -> bool:
        self._data = data
        return True

    def clear(self) -> None:
        """Upstream keeps a static transform through clear()."""

    def __len__(self) -> int:
        return 1

    def latest_time_and_parent(self) -> tuple[int, int]:
        return 0, self._data.frame_id

    def latest_stamp(self) -> int:
        return 0

    def oldest_stamp(self) -> int:
        return 0


Cache = TimeCache | StaticCache
