"""The TF tree as the 3D view needs it: each frame's latest pose in the fixed frame.

RViz looks each frame up at the latest time the tree has (time 0), so a view only ever
needs the newest transform of each edge; keeping no history makes taking `/tf` at 50 Hz
and resolving 20 frames at the display rate cost the kernel about a percent of a core
(`bench/bench_scene_view.py`). Lessons that need tf2's semantics (interpolation, the 10 s
cache, its exceptions) use `tf2_ros.Buffer` (robot_lab.tf2); this is only what a picture
needs. The kit's BufferCore was measured for this job: 19 inserts 49 µs, but 19 lookups at
time 0 take 0.62 ms (2.5 % of a core at the view's 40 Hz) against 0.06 ms for `resolve`
here, and the view's whole budget is 5 %.

Poses are tuples `(x, y, z, qx, qy, qz, qw)`: what the browser takes, no numpy.
"""

from __future__ import annotations

import math
import struct
from typing import TypeAlias

__all__ = ['IDENTITY', 'FrameTree', 'Pose', 'compose', 'inverse']

Pose: TypeAlias = tuple[float, float, float, float, float, float, float]

IDENTITY: Pose = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)

# tf2's graph depth limit: a longer chain is a loop
MAX_DEPTH = 1000


def _rotate(q: tuple[float, float, float, float], v: tuple[float, float, float]
            ) -> tuple[float, float, float]:
    """v rotated by the unit quaternion q (x, y, z, w): v + 2w(u×v) + 2u×(u×v)."""
    qx, qy, qz, qw = q
    vx, vy, vz = v
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (vx + qw * tx + (qy * tz - qz * ty),
            vy + qw * ty + (qz * tx - qx * tz),
            vz + qw * tz + (qx * ty - qy * tx))


def compose(a: Pose, b: Pose) -> Pose:
    """a ∘ b: the pose b (given in a's frame) in the frame a is given in."""
    ax, ay, az, aqx, aqy, aqz, aqw = a
    bx, by, bz, bqx, bqy, bqz, bqw = b
    rx, ry, rz = _rotate((aqx, aqy, aqz, aqw), (bx, by, bz))
    return (ax + rx, ay + ry, az + rz,
            aqw * bqx + aqx * bqw + aqy * bqz - aqz * bqy,
            aqw * bqy - aqx * bqz + aqy * bqw + aqz * bqx,
            aqw * bqz + aqx * bqy - aqy * bqx + aqz * bqw,
            aqw * bqw - aqx * bqx - aqy * bqy - aqz * bqz)


def inverse(a: Pose) -> Pose:
    x, y, z, qx, qy, qz, qw = a
    tx, ty, tz = _rotate((-qx, -qy, -qz, qw), (x, y, z))
    return (-tx, -ty, -tz, -qx, -qy, -qz, qw)


def normalised(pose: Pose) -> Pose | None:
    """The pose with a unit quaternion; None for NaN or a zero quaternion (tf2 refuses
    those: TF_NAN_INPUT, TF_DENORMALIZED_QUATERNION)."""
    x, y, z, qx, qy, qz, qw = pose
    norm2 = qx * qx + qy * qy + qz * qz + qw * qw
    if not math.isfinite(x + y + z + norm2):  # a NaN or an infinity anywhere
        return None
    if abs(norm2 - 1.0) < 1e-12:
        return pose  # the usual case: nothing to compute
    if norm2 < 1e-12:
        return None
    norm = math.sqrt(norm2)
    return (x, y, z, qx / norm, qy / norm, qz / norm, qw / norm)


class FrameTree:
    """Edges child → (parent, pose of child in parent), newest only."""

    def __init__(self) -> None:
        self.edges: dict[str, tuple[str, Pose]] = {}
        self.static: set[str] = set()
        self.version = 0  # bumps when an edge is added, moved to another parent or removed
        self.rejected: dict[str, str] = {}  # child → why its last transform was not taken

    def put(self, parent: str, child: str, pose: Pose, static: bool = False) -> bool:
        """Take one transform; True if anything changed."""
        parent, child = parent.lstrip('/'), child.lstrip('/')
        if not parent or not child or parent == child:
            self.rejected[child or '?'] = (f'a transform from [{parent}] to [{child}] '
                                           'was ignored (tf2 refuses it too)')
            return False
        good = normalised(pose)
        if good is None:
            self.rejected[child] = (f'the transform from [{parent}] to [{child}] has NaN or a '
                                    'zero quaternion: ignored, as tf2 ignores it')
            return False
        self.rejected.pop(child, None)
        old = self.edges.get(child)
        if old is not None and old == (parent, good):
            return False
        if old is None or old[0] != parent:
            self.version += 1
        self.edges[child] = (parent, good)
        if static:
            self.static.add(child)
        else:
            self.static.discard(child)
        return True

    def frames(self) -> set[str]:
        return set(self.edges) | {parent for parent, _ in self.edges.values()}

    def tree(self) -> list[tuple[str, str]]:
        """(child, parent) pairs, sorted: what the TF display draws its arrows along."""
        return sorted((child, parent) for child, (parent, _) in self.edges.items())

    def root_of(self, frame: str) -> tuple[str, Pose] | None:
        """(the root of frame's tree, frame's pose in it); None on a loop."""
        pose = IDENTITY
        current = frame
        for _ in range(MAX_DEPTH):
            edge = self.edges.get(current)
            if edge is None:
                return current, pose
            parent, step = edge
            pose = compose(step, pose)
            current = parent
        return None

    def resolve(self, fixed: str) -> dict[str, Pose | None]:
        """Every known frame's pose in `fixed` (None: not connected to it)."""
        roots: dict[str, tuple[str, Pose] | None] = {}
        for frame in self.frames():
            roots[frame] = self._root_cached(frame, roots)
        anchor = roots.get(fixed) if fixed in roots else None
        if anchor is None:
            return dict.fromkeys(roots)
        fixed_root, fixed_pose = anchor
        to_fixed = inverse(fixed_pose)
        out: dict[str, Pose | None] = {}
        for frame, found in roots.items():
            if found is None or found[0] != fixed_root:
                out[frame] = None
            else:
                out[frame] = compose(to_fixed, found[1])
        return out

    def _root_cached(self, frame: str, memo: dict[str, tuple[str, Pose] | None]
                     ) -> tuple[str, Pose] | None:
        """root_of with the frames already resolved reused (a 20-link chain: 20 steps,
        not 210)."""
        chain: list[tuple[str, Pose]] = []
        current = frame
        found: tuple[str, Pose] | None = None
        for _ in range(MAX_DEPTH):
            if current in memo:
                found = memo[current]
                break
            edge = self.edges.get(current)
            if edge is None:
                found = (current, IDENTITY)
                memo[current] = found
                break
            chain.append((current, edge[1]))
            current = edge[0]
        else:
            return None
        for name, step in reversed(chain):
            found = None if found is None else (found[0], compose(found[1], step))
            memo[name] = found
        return found

    def why_not(self, frame: str, fixed: str) -> str:
        """Why `frame` has no pose in `fixed`, in a few words."""
        known = self.frames()
        if frame in self.rejected:
            return self.rejected[frame]
        if frame not in known:
            return f'frame [{frame}] does not exist'
        if fixed not in known:
            return f'fixed frame [{fixed}] does not exist'
        a, b = self.root_of(frame), self.root_of(fixed)
        if a is None or b is None:
            return f'the TF tree above [{frame if a is None else fixed}] has a loop'
        return (f'[{frame}] and [{fixed}] are not part of the same tree '
                f'(their roots are [{a[0]}] and [{b[0]}])')


_U32 = {'<': struct.Struct('<I'), '>': struct.Struct('>I')}
_POSE = {'<': struct.Struct('<7d'), '>': struct.Struct('>7d')}


def parse_tf_message(raw: bytes) -> list[tuple[str, str, Pose]]:
    """A serialized tf2_msgs/TFMessage (CDR, as a raw subscription hands it over) →
    [(parent, child, pose)], stamps skipped.

    rclpy builds a Python object per field: 0.68 ms for a 19-transform message, 3.4 % of a
    core at 50 Hz, most of the view's cost; reading the doubles straight from the bytes
    costs a few percent of that. Raises ValueError on an encoding it does not know
    (the caller then lets rclpy deserialize).
    """
    if len(raw) < 8 or raw[0] != 0 or raw[1] not in (0, 1):
        raise ValueError('not plain CDR')
    order = '<' if raw[1] == 1 else '>'
    u32, seven = _U32[order].unpack_from, _POSE[order].unpack_from
    # Alignment counts from after the 4-byte encapsulation header: offset - 4.
    out: list[tuple[str, str, Pose]] = []
    try:
        (count,) = u32(raw, 4)
        offset = 8
        for _ in range(count):
            offset += (-offset) % 4 + 8  # stamp: int32 sec, uint32 nanosec
            (length,) = u32(raw, offset)  # header.frame_id, with its NUL
            parent = raw[offset + 4:offset + 3 + length].decode('utf-8')
            offset += 4 + length
            offset += (-offset) % 4
            (length,) = u32(raw, offset)  # child_frame_id
            child = raw[offset + 4:offset + 3 + length].decode('utf-8')
            offset += 4 + length
            offset += (-(offset - 4)) % 8
            out.append((parent, child, seven(raw, offset)))
            offset += 56
    except struct.error as err:
        raise ValueError(f'truncated TFMessage: {err}') from err
    return out
