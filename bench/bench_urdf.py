"""robot_state_publisher's cost per /joint_states message, in the kit's pure Python.

Per model: microseconds to turn one JointState into the /tf message (mimic positions,
each moving joint's pose and quaternion, the TransformStamped list), as
`RobotStatePublisher.publish_transforms` does, without DDS; next to it yourdfpy's
`update_cfg` (the independent library the tests compare against; its figure includes
the scene graph's update). Models: urdf_tutorial's R2D2 (08, 8 moving joints of 16
links) and a 20-link chain of revolute joints (the scene view's goal robot). Also the
time to parse each URDF. Medians of --runs runs of --repeat calls.

    .venv/bin/python bench/bench_urdf.py [--runs 5] [--repeat 500]
"""

from __future__ import annotations

import argparse
import io
import random
import statistics
import subprocess
import sys
import time
from pathlib import Path

import yourdfpy
from builtin_interfaces.msg import Time

from robot_lab.urdf.joints import joint_table
from robot_lab.urdf.kinematics import joint_pose, mimic_positions
from robot_lab.urdf.model import Robot, parse_urdf
from robot_lab.urdf.state_publisher import transform_message

SHARE = Path(sys.prefix) / 'share' / 'urdf_tutorial' / 'urdf'


def chain(links: int) -> str:
    joints = ''.join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0 0 0.1" rpy="0.1 0 0"/><axis xyz="0 1 0"/>'
        f'<limit lower="-2" upper="2" effort="1" velocity="1"/></joint>'
        for i in range(links - 1))
    names = ''.join(f'<link name="l{i}"/>' for i in range(links))
    return f'<robot name="chain">{names}{joints}</robot>'


def one_message(robot: Robot, positions: dict[str, float], stamp: Time) -> list[object]:
    full = mimic_positions(robot, positions)
    return [transform_message(joint_pose(j, full[j.name]), j.parent, j.child, stamp)
            for j in robot.joints.values() if j.moves and j.name in full]


def per_call(fn: object, repeat: int, runs: int) -> float:
    """Median over runs of the mean microseconds per call."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        for _ in range(repeat):
            fn()  # type: ignore[operator]
        times.append((time.perf_counter() - start) / repeat * 1e6)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument('--runs', type=int, default=5)
    parser.add_argument('--repeat', type=int, default=500)
    args = parser.parse_args()
    xacro = Path(sys.executable).parent / 'xacro'
    models = {
        'R2D2 (08-macroed)': subprocess.run([str(xacro), str(SHARE / '08-macroed.urdf.xacro')],
                                            capture_output=True, text=True,
                                            check=True).stdout,
        '20-link chain': chain(20),
    }
    stamp = Time(sec=1)
    print(f'{"model":<20} {"links":>5} {"moving":>6} {"parse ms":>9} '
          f'{"rsp /tf µs":>11} {"yourdfpy µs":>12}')
    for name, text in models.items():
        parse_ms = per_call(lambda text=text: parse_urdf(text), 20, args.runs) / 1000
        robot = parse_urdf(text)
        rng = random.Random(0)
        free = joint_table(robot).free
        positions = {n: rng.uniform(j.lower, j.upper) for n, j in free.items()}
        ours = per_call(lambda r=robot, p=positions: one_message(r, p, stamp), args.repeat,
                        args.runs)
        ref = yourdfpy.URDF.load(io.StringIO(text), load_meshes=False,
                                 build_scene_graph=True, filename_handler=lambda f: f)
        theirs = per_call(lambda r=ref, p=positions: r.update_cfg(p), args.repeat, args.runs)
        moving = sum(j.moves for j in robot.joints.values())
        print(f'{name:<20} {len(robot.links):>5} {moving:>6} {parse_ms:>9.2f} '
              f'{ours:>11.0f} {theirs:>12.0f}')


if __name__ == '__main__':
    main()
