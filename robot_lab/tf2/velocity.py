"""BufferCore::lookupVelocity: a frame's twist, averaged over an interval, as tf2 computes
it (tf2_py's lookupVelocityCore / lookupVelocityFullCore)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from robot_lab.tf2 import linear_math as lm
from robot_lab.tf2.time_cache import seconds

if TYPE_CHECKING:
    from robot_lab.tf2.buffer_core import BufferCore


def time_from_sec(t: float) -> int:
    """tf2::timeFromSec: whole seconds by floor, the rest rounded to nanoseconds."""
    sec = math.floor(t)
    nsec = round((t - sec) * 1e9)
    return sec * 10**9 + nsec


def lookup_velocity(core: BufferCore, tracking: str, observation: str, reference: str,
                    point: tuple[float, float, float], point_frame: str, time: int,
                    interval: int) -> tuple[lm.Vec, lm.Vec]:
    """(linear, angular) velocity of `tracking` seen from `observation`, in `reference`."""
    code, latest, _ = core.latest_common_time(core.frame_number(observation),
                                              core.frame_number(tracking))
    latest = latest if code == 0 else 0
    time_s = seconds(time)
    interval_s = interval / 1e9
    end_time = min(time_s + interval_s * 0.5, seconds(latest))
    start_time = max(0.00001 + interval_s, end_time) - interval_s
    corrected = end_time - start_time
    (start_vec, start_quat), _ = core._lookup(observation, tracking, time_from_sec(start_time))
    (end_vec, end_quat), _ = core._lookup(observation, tracking, time_from_sec(end_time))
    temp = lm.stored_rotation(lm.multiply(lm.inverse(start_quat), end_quat))
    s_squared = 1.0 - temp[3] ** 2
    if s_squared < 10.0 * 2.220446049250313e-16:
        axis: lm.Vec = (1.0, 0.0, 0.0)
    else:
        s = math.sqrt(s_squared)
        axis = (temp[0] / s, temp[1] / s, temp[2] / s)
    o = lm.rotate(start_quat, axis)
    angle = 2.0 * math.acos(max(-1.0, min(1.0, temp[3])))
    twist_vel = tuple((e - b) / corrected for b, e in zip(start_vec, end_vec, strict=True))
    twist_rot = tuple(c * (angle / corrected) for c in o)
    (inv_vec, inv_quat), _ = core._lookup(reference, tracking, time_from_sec(time_s))
    out_rot = lm.rotate(inv_quat, (twist_rot[0], twist_rot[1], twist_rot[2]))
    out_vel = lm.add(lm.rotate(inv_quat, (twist_vel[0], twist_vel[1], twist_vel[2])),
                     lm.cross(inv_vec, out_rot))

    def transform_point(target: str, source: str, p: lm.Vec) -> lm.Vec:
        (vec, quat), _ = core._lookup(target, source, time_from_sec(time_s))
        return lm.add(lm.rotate(quat, p), vec)

    origin = transform_point(reference, tracking, lm.ZERO)
    desired = transform_point(reference, point_frame, (float(point[0]), float(point[1]),
                                                      float(point[2])))
    delta = (desired[0] - origin[0], desired[1] - origin[1], desired[2] - origin[2])
    # tf2 writes `out_rot * delta`: Vector3's product, component by component.
    out_vel = (out_vel[0] + out_rot[0] * delta[0], out_vel[1] + out_rot[1] * delta[1],
               out_vel[2] + out_rot[2] * delta[2])
    return out_vel, out_rot
