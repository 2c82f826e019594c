"""Ground truth against odometry: the simulated body goes where DiffDrive says it went.

A lesson grades stopping distance against the simulator's ground truth, while the
student's controller reads /odom: the two must agree, as they do with Gazebo's DiffDrive
on flat ground. Each case commands a motion, stops, lets the robot come to rest, and
compares the root link's pose in the world with the odometry and with the command.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from robot_lab.sim.sample_robot import WHEEL_RADIUS, diffbot_urdf
from robot_lab.sim.simulation import Simulation

pytestmark = pytest.mark.no_ros  # the simulator alone: no DDS, no domain


def _motion(linear: float, angular: float, seconds: float = 2.0
            ) -> tuple[tuple[float, float], tuple[float, float]]:
    """(distance, turn) of the body and of the odometry, from rest to rest."""
    odom: list[dict[str, Any]] = []
    sim = Simulation('empty.sdf', warn=pytest.fail,
                     on_publish=lambda topic, kind, msg: odom.append(msg) if topic == '/odom'
                     else None)
    sim.spawn(diffbot_urdf(), 'diffbot', (0.0, 0.0, WHEEL_RADIUS + 0.001))
    sim.step(200)  # settle on the wheels

    def odometry() -> tuple[float, float, float]:
        pose = odom[-1]['pose']
        q = pose['orientation']
        yaw = math.atan2(2 * (q['w'] * q['z'] + q['x'] * q['y']),
                         1 - 2 * (q['y'] ** 2 + q['z'] ** 2))
        return pose['position']['x'], pose['position']['y'], yaw

    body0, odom0 = sim.body_pose('diffbot'), odometry()
    sim.command('/cmd_vel', {'linear': {'x': linear}, 'angular': {'z': angular}})
    sim.step(round(seconds / sim.info.step))
    sim.command('/cmd_vel', {'linear': {'x': 0.0}, 'angular': {'z': 0.0}})
    sim.step(1000)  # to rest
    body1, odom1 = sim.body_pose('diffbot'), odometry()

    def change(a: tuple[float, float, float], b: tuple[float, float, float]
               ) -> tuple[float, float]:
        return math.hypot(b[0] - a[0], b[1] - a[1]), math.remainder(b[2] - a[2], math.tau)

    return change(body0, body1), change(odom0, odom1)


def test_a_straight_metre_is_a_metre_on_the_ground() -> None:
    (body, _), (odom, _) = _motion(0.5, 0.0)
    assert body == pytest.approx(odom, rel=0.02)
    assert body == pytest.approx(1.0, rel=0.02)  # as commanded: 0.5 m/s for 2 s


def test_a_quarter_turn_in_place_is_a_quarter_turn_on_the_ground() -> None:
    (drift, body), (_, odom) = _motion(0.0, math.pi / 4)
    assert body == pytest.approx(odom, rel=0.02)
    assert body == pytest.approx(math.pi / 2, rel=0.02)
    assert drift < 0.01  # it turned about its own axle


def test_an_arc_ends_where_odometry_says() -> None:
    (body_d, body_t), (odom_d, odom_t) = _motion(0.3, 0.5)
    assert body_d == pytest.approx(odom_d, rel=0.02)
    assert body_t == pytest.approx(odom_t, rel=0.02)
