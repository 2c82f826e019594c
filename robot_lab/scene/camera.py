"""Where the 3D view's camera is: an eye and a target set from code, or one that sees a box.

`look_at` (RViz's Orbit view, set from code) takes an eye and a target checked here. The
bundle's own first camera sits 2.4 m from the origin, right for a robot on a desk but
inside a 4 m room, where two walls stay behind it. `overview` computes an eye above and
behind (-x, the way a robot spawned at the origin faces away from it) from which every
corner of the box is inside the picture, so a world is seen whole before anyone orbits.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from robot_lab.errors import GraphError

if TYPE_CHECKING:
    from robot_lab.scene.displays import Markers

__all__ = ['FOV', 'Vec3', 'camera_values', 'extent', 'eye_and_target', 'overview']

Vec3 = tuple[float, float, float]
FOV = 50.0  # the bundle's vertical field of view (degrees); a view is wider than tall
_PITCH = math.radians(50.0)  # looking down: the floor and every wall's inner face show
_MARGIN = 1.08


def camera_values(eye: Vec3, target: Vec3) -> list[float]:
    """The canvas's camera trait (eye x, y, z, target x, y, z); a GraphError if the two
    are not two different finite points."""
    try:
        values = [float(v) for v in (*eye, *target)]
    except (TypeError, ValueError):
        values = []
    if len(values) != 6 or not all(map(math.isfinite, values)) or values[:3] == values[3:]:
        raise GraphError(f'look_at(eye={eye!r}, target={target!r}): not a camera',
                         fix='give two different points (x, y, z) in metres, e.g. '
                         'view.look_at(eye=(-4, 0, 3), target=(0, 0, 0))')
    return values


def eye_and_target(values: list[float]) -> tuple[Vec3, Vec3] | None:
    """The eye and target in a camera trait (None: empty, the view's first camera)."""
    v = values
    return ((v[0], v[1], v[2]), (v[3], v[4], v[5])) if v else None


def _rotate(q: tuple[float, ...], v: Vec3) -> Vec3:
    """v rotated by the unit quaternion q = (x, y, z, w)."""
    x, y, z, w = q
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz,
            v[2] + w * tz + x * ty - y * tx)


def extent(markers: Markers) -> tuple[Vec3, Vec3] | None:
    """The box (low and high corner, in the markers' frame) holding every shape the display
    draws: each shape's scaled box turned by its pose; None when it draws nothing."""
    corners: list[Vec3] = []
    with markers._lock:
        ops = list(markers.items.values())
    for op in ops:
        pose, scale, points = op['pose'], op['scale'], op['points']
        assert isinstance(pose, list) and isinstance(scale, list) and isinstance(points, list)
        half = [float(v) / 2 for v in scale]
        local: list[Vec3] = [(points[i], points[i + 1], points[i + 2])
                             for i in range(0, len(points), 3)] or [
            (sx * half[0], sy * half[1], sz * half[2])
            for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        for v in local:
            r = _rotate(tuple(pose[3:7]), v)
            corners.append((pose[0] + r[0], pose[1] + r[1], pose[2] + r[2]))
    if not corners:
        return None
    xs, ys, zs = zip(*corners, strict=True)
    return (min(xs), min(ys), min(zs)), (max(xs), max(ys), max(zs))


def overview(low: Vec3, high: Vec3, fov: float = FOV,
             aspect: float = 1.25) -> tuple[Vec3, Vec3]:
    """An eye and a target: the box's centre seen from above and behind (-x), as near as
    keeps all eight corners in a picture `fov` degrees tall and `aspect` times as wide
    (a notebook's view is 960 × 480 at most, narrower beside JupyterLab's side bar)."""
    target = ((low[0] + high[0]) / 2, (low[1] + high[1]) / 2, (low[2] + high[2]) / 2)
    forward = (math.cos(_PITCH), 0.0, -math.sin(_PITCH))
    up = (math.sin(_PITCH), math.cos(_PITCH))  # its x and z (no y); right is -y
    slope = math.tan(math.radians(fov) / 2)
    distance = 0.5
    for x in (low[0], high[0]):
        for y in (low[1], high[1]):
            for z in (low[2], high[2]):
                c = (x - target[0], y - target[1], z - target[2])
                ahead = sum(a * b for a, b in zip(c, forward, strict=True))
                lift = c[0] * up[0] + c[2] * up[1]
                across = max(abs(c[1]) / aspect, abs(lift))
                distance = max(distance, across / slope - ahead)  # depth = distance + ahead
    distance *= _MARGIN
    eye = (target[0] - distance * forward[0], target[1], target[2] - distance * forward[2])
    return eye, target
