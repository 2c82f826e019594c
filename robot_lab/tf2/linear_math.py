"""The few pieces of tf2's LinearMath the buffer needs, on plain tuples.

Quaternions are (x, y, z, w) and vectors (x, y, z), as in geometry_msgs. The operations
follow tf2's definitions to the letter (a stored rotation goes through a 3x3 matrix, the
inverse is the conjugate, slerp takes the short way), so a lookup's numbers are the ones a
Jazzy install prints, down to the sign of w.
"""

from __future__ import annotations

import math

Quat = tuple[float, float, float, float]
Vec = tuple[float, float, float]
Matrix = tuple[Vec, Vec, Vec]

IDENTITY: Quat = (0.0, 0.0, 0.0, 1.0)
ZERO: Vec = (0.0, 0.0, 0.0)


def matrix_from_quaternion(q: Quat) -> Matrix:
    """Matrix3x3::setRotation: a rotation matrix whatever the quaternion's length (0 gives
    NaNs, as C++'s division by zero does)."""
    x, y, z, w = q
    d = x * x + y * y + z * z + w * w
    s = 2.0 / d if d != 0.0 else math.inf
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    return ((1.0 - (yy + zz), xy - wz, xz + wy),
            (xy + wz, 1.0 - (xx + zz), yz - wx),
            (xz - wy, yz + wx, 1.0 - (xx + yy)))


def quaternion_from_matrix(m: Matrix) -> Quat:
    """Matrix3x3::getRotation (w >= 0 when the trace is positive)."""
    trace = m[0][0] + m[1][1] + m[2][2]
    temp = [0.0, 0.0, 0.0, 0.0]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0)
        temp[3] = s * 0.5
        s = 0.5 / s
        temp[0] = (m[2][1] - m[1][2]) * s
        temp[1] = (m[0][2] - m[2][0]) * s
        temp[2] = (m[1][0] - m[0][1]) * s
    else:
        # the largest diagonal element
        i = (2 if m[1][1] < m[2][2] else 1) if m[0][0] < m[1][1] else (
            2 if m[0][0] < m[2][2] else 0)
        j, k = (i + 1) % 3, (i + 2) % 3
        radicand = m[i][i] - m[j][j] - m[k][k] + 1.0
        s = math.sqrt(radicand) if radicand >= 0.0 else math.nan
        temp[i] = s * 0.5
        s = 0.5 / s if s != 0.0 else math.inf
        temp[3] = (m[k][j] - m[j][k]) * s
        temp[j] = (m[j][i] + m[i][j]) * s
        temp[k] = (m[k][i] + m[i][k]) * s
    return (temp[0], temp[1], temp[2], temp[3])


def stored_rotation(q: Quat) -> Quat:
    """What tf2::Transform keeps of a message's quaternion: normalised by its matrix."""
    if q == IDENTITY:
        return IDENTITY
    return quaternion_from_matrix(matrix_from_quaternion(q))


def multiply(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by + ay * bw + az * bx - ax * bz,
            aw * bz + az * bw + ax * by - ay * bx,
            aw * bw - ax * bx - ay * by - az * bz)


def inverse(q: Quat) -> Quat:
    return (-q[0], -q[1], -q[2], q[3])


def rotate(q: Quat, v: Vec) -> Vec:
    """quatRotate: q * v * q^-1 (the conjugate, as tf2 computes it)."""
    x, y, z, w = q
    vx, vy, vz = v
    # q * (v, 0)
    px = w * vx + y * vz - z * vy
    py = w * vy + z * vx - x * vz
    pz = w * vz + x * vy - y * vx
    pw = -x * vx - y * vy - z * vz
    # ... * (-x, -y, -z, w)
    return (pw * -x + px * w + py * -z - pz * -y,
            pw * -y + py * w + pz * -x - px * -z,
            pw * -z + pz * w + px * -y - py * -x)


def add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def negate(a: Vec) -> Vec:
    return (-a[0], -a[1], -a[2])


def cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def lerp(a: Vec, b: Vec, ratio: float) -> Vec:
    """Vector3::setInterpolate3."""
    s = 1.0 - ratio
    return (s * a[0] + ratio * b[0], s * a[1] + ratio * b[1], s * a[2] + ratio * b[2])


def slerp(a: Quat, b: Quat, t: float) -> Quat:
    """Quaternion::slerp, the shortest path between `a` and `b`."""
    dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    s = math.sqrt((a[0] ** 2 + a[1] ** 2 + a[2] ** 2 + a[3] ** 2)
                  * (b[0] ** 2 + b[1] ** 2 + b[2] ** 2 + b[3] ** 2))
    theta = math.acos(max(-1.0, min(1.0, abs(dot) / s))) if s else 0.0
    if theta == 0.0:
        return a
    d = 1.0 / math.sin(theta)
    s0 = math.sin((1.0 - t) * theta)
    s1 = math.sin(t * theta)
    if dot < 0:
        s1 = -s1
    return ((a[0] * s0 + b[0] * s1) * d, (a[1] * s0 + b[1] * s1) * d,
            (a[2] * s0 + b[2] * s1) * d, (a[3] * s0 + b[3] * s1) * d)


def compose(a: tuple[Vec, Quat], b: tuple[Vec, Quat]) -> tuple[Vec, Quat]:
    """Transform a * b: b's pose expressed through a."""
    return add(rotate(a[1], b[0]), a[0]), multiply(a[1], b[1])


def euler_from_quaternion(q: Quat) -> Vec:
    """(roll, pitch, yaw) of Matrix3x3::getRPY (solution 1), as tf2_echo prints them."""
    m = matrix_from_quaternion(q)
    if abs(m[2][0]) >= 1.0:
        pitch = math.pi / 2.0 if m[2][0] < 0 else -math.pi / 2.0
        return math.atan2(m[2][1], m[2][2]), pitch, 0.0
    pitch = -math.asin(m[2][0])
    c = math.cos(pitch)
    roll = math.atan2(m[2][1] / c, m[2][2] / c)
    yaw = math.atan2(m[1][0] / c, m[0][0] / c)
    return roll, pitch, yaw


def quaternion_from_euler(roll: float, pitch: float, yaw: float) -> Quat:
    """Quaternion::setRPY (fixed axes: roll about X, then pitch about Y, then yaw about Z)."""
    hr, hp, hy = roll * 0.5, pitch * 0.5, yaw * 0.5
    cr, sr = math.cos(hr), math.sin(hr)
    cp, sp = math.cos(hp), math.sin(hp)
    cy, sy = math.cos(hy), math.sin(hy)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)
