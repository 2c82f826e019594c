"""Choosing the simulator's physics engine: MuJoCo against PyBullet, measured here.

Both engines load the kit's sample robot (`robot_lab.sim.sample_robot`, a diff-drive base
with a caster and a 360-beam lidar link) by their own URDF loaders, on a floor, in front of
a wall, with a 1 ms fixed step. Each figure is the median of `--runs` runs:

- physics steps per second (the robot resting on its wheels, contacts active);
- 360-beam scans per second (one ray batch: `mj_multiRay`, `rayTestBatch`);
- determinism: two runs of 2000 steps with the same wheel commands end in bit-identical
  states (True/False);
- urdf_tutorial's models 01–07 (no xacro): geoms loaded, or the engine's refusal.

Measured 2026-12-06 on this 2-core host while seven other sessions ran (load average 9-11),
median of 5 runs:
  MuJoCo 4.0.1:   52.6k steps/s, 19.4k scans/s, deterministic; urdf_tutorial 01-05 load
                  with 0 geoms (visual-only links dropped), 06 refused ("mass and inertia of
                  moving bodies must be larger than mjMINVAL"), 07 refused (package:// path)
  PyBullet 3.2.7: 16.3k steps/s, 1.56k scans/s, deterministic; 01-07 load (links without
                  inertia get mass 1 and a printed warning each; 07's package:// meshes are
                  dropped)
MuJoCo is chosen: 3.2x PyBullet's step rate and 12x its scan rate (the two loops a lidar
robot spends its time in), Apache-2.0 (PyBullet is zlib, also fine), and an `MjSpec` API
that builds a model body by body, so the kit reads the URDF itself and fixes what MuJoCo's
own loader refuses (inertia, package://, .dae, the free base) with a warning naming the
link. Its wheels' velocity servos need the implicit-in-velocity integrator (implicitfast):
with Euler a stiff servo on a light wheel diverges in 4 ms.

Then the kit's simulator itself (`--system`; issue 50's bench lines), the room world with the
sample robot and its 360-beam 10 Hz lidar:
- headless maximum speed: `Simulation.step()` as fast as it goes, in simulated seconds per
  wall second (goal >= 20x);
- the real-time factor of the simulator process (`gz_sim -r room.sdf`, real time), from
  its /world/room/stats as Gazebo reports it, while `--busy` busy loops stand in for
  students' kernels (goal >= 1.0), and the process's CPU
  (goal <= 25 % of a core per simulated student);
- start to first /scan: from starting `gz_sim`, `create` and `parameter_bridge` to a ROS
  subscriber's first LaserScan (goal <= 3 s). Needs a domain: run it in `unshare --net`.

Measured 2026-12-06, same host and load, `--system --runs 3 --seconds 5 --busy 1`, after
the imu joined the sample robot: headless 31.4x real time (16.9x in an earlier run: the
host's load moves it; bare mj_step ran 14-48 us a step, the systems' Python adds about as
much again); real-time factor 0.999 beside a busy loop; the simulator's process 5.4 % of a
core; start to first /scan 4.95 s (3.2-6.4 s over runs; not yet at the goal).

The start taken apart (each process's own log line marks its stage): this bench used to
start its subscriber's ROS only after `create` had returned, a wait no lab has (a launch
file starts every process at once); it now starts all four together. On an idle core the
simulator serves at 1.1 s, `create` has spawned at 1.2 s, the bridge's node is up at
1.4 s (0.2-0.35 s importing rclpy, 0.35-0.5 s of wall in its first create_node for 0.12 s
of CPU: the DDS participant) and the first /scan arrives 0.03-0.1 s later (discovery with
the kit's profile is not the cost). Under this host's load (load average 18-20 on 2
cores) every stage stretches alike: it is CPU, not waiting. The simulator now listens
before it imports MuJoCo, so `create` and the bridge connect at once instead of polling.
`--system --runs 5 --seconds 1 --busy 1`, load average 18-20: before (serial bench) 2.92 s;
after, all at once: 3.40 s with stages subscriber 0.11, sim serving 2.89, spawned 2.89,
bridge node 3.35, publisher seen 3.39, first /scan 3.40 (medians) -- the bridge's ROS
start and the simulator's import, both CPU-bound, are the path. The same command at load
average 7: start to first /scan 1.28 s (subscriber 0.06, sim serving 1.17, spawned 1.18,
bridge node 1.23, publisher seen 1.25), at the goal; headless 26.3x, factor 0.996, 5.0 %.
Listening before the import is no measurable gain: A/B against the old server, medians
of 3-5 at load 7-9, first /scan 0.91/0.80/1.21 s (old) vs 0.54/0.75/1.58 s (new), noise
larger than any difference. The figure is set by the host's load, not by a wait.
After the wheel fixes (wheels.py) the headless speed rose: 54-90x in three runs at that
load, the robot no longer bouncing on its contacts.

The real-time factor's 0.996-0.999 was this bench's window, not the simulator's pacing
(whose steps were already due at absolute deadlines): it took its start time, then waited
up to a /clock period (10 ms of sim time) plus the delivery for the first /clock, so the
sim time it counted began late; 5 ms in 5 s is 0.999. It now measures as Gazebo reports it,
from /world/room/stats: the server's sim_time over its real_time (running time), between a
first and a last message 5 s apart, beside the mean of the messages' real_time_factor.
`--system --runs 5 --seconds 5 --busy 1`, load average 7-14, 2026-12-06: the server before
this change (commit fcdf9d9) 1.0000 (runs 0.9999-1.0001; fields 0.9999), after 1.0000 (runs
1.0000-1.0001; fields 1.0000); the old window on the new server still read 0.999. Again
after the paused start, ControlWorld and SDF robots, at load average 22: 1.0000 (runs
1.0000-1.0001), headless 29.0x, simulator CPU 5.1 %, first /scan 3.30 s.

Usage: python bench/bench_sim.py [--runs N] [--system [--busy N] [--seconds S]]
(PyBullet from PYBULLET_PATH, a `pip install --target` folder, when the venv lacks it)
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from robot_lab.sim.sample_robot import diffbot_urdf  # noqa: E402

TUTORIAL = REPO / 'robot_lab/data/ament_packages/urdf_tutorial/urdf'
BEAMS = 360
STEP = 0.001


def _rate(run: Callable[[], None], seconds: float = 1.0) -> float:
    count, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        run()
        count += 1
    return count / (time.perf_counter() - start)


def _directions() -> list[tuple[float, float, float]]:
    return [(math.cos(2 * math.pi * i / BEAMS), math.sin(2 * math.pi * i / BEAMS), 0.0)
            for i in range(BEAMS)]


def bench_mujoco(urdf: Path) -> dict[str, object]:
    import mujoco
    import numpy as np

    def build() -> tuple[mujoco.MjModel, mujoco.MjData]:
        spec = mujoco.MjSpec.from_file(str(urdf))
        spec.option.timestep = STEP
        # the wheels' velocity servo is stiff for their small inertia: implicit in velocity
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        root = spec.worldbody.first_body()
        root.add_freejoint()
        root.pos = [0, 0, 0.06]
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1])
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 2, 0.5],
                                pos=[2, 0, 0.5])
        for joint in ('left_wheel_joint', 'right_wheel_joint'):
            spec.add_actuator(target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT,
                              gaintype=mujoco.mjtGain.mjGAIN_FIXED, gainprm=[5.0] + [0.0] * 9,
                              biastype=mujoco.mjtBias.mjBIAS_AFFINE,
                              biasprm=[0.0, 0.0, -5.0] + [0.0] * 7)
        model = spec.compile()
        return model, mujoco.MjData(model)

    model, data = build()
    data.ctrl[:] = [10.0, 10.0]
    steps = _rate(lambda: mujoco.mj_step(model, data))
    if not np.isfinite(data.qpos).all() or data.qpos[0] < 0.5:
        raise RuntimeError(f'MuJoCo run diverged or did not drive: {data.qpos[:3]}')
    vec = np.array(_directions(), dtype=np.float64).ravel()
    pnt = np.array([0.0, 0.0, 0.2])
    geomid = np.zeros(BEAMS, dtype=np.int32)
    dist = np.zeros(BEAMS, dtype=np.float64)
    scans = _rate(lambda: mujoco.mj_multiRay(model, data, pnt, vec, None, True, 1, geomid,
                                             dist, None, BEAMS, 12.0))

    def trajectory() -> bytes:
        m, d = build()
        for i in range(2000):
            d.ctrl[:] = [10.0, 6.0 + (i % 7)]
            mujoco.mj_step(m, d)
        return d.qpos.tobytes() + d.qvel.tobytes()

    loads = {}
    for path in sorted(TUTORIAL.glob('0[1-7]*.urdf')):
        try:
            loads[path.name[:2]] = f'{mujoco.MjSpec.from_file(str(path)).compile().ngeom} geoms'
        except Exception as error:
            loads[path.name[:2]] = 'refused: ' + str(error).splitlines()[0][:60]
    return {'steps/s': steps, 'scans/s': scans, 'deterministic': trajectory() == trajectory(),
            'urdf_tutorial': loads}


def bench_pybullet(urdf: Path) -> dict[str, object]:
    extra = os.environ.get('PYBULLET_PATH')
    if extra:
        sys.path.insert(0, extra)
    try:
        import pybullet
    except ImportError:
        return {'missing': 'pip install --target DIR pybullet==3.2.7; PYBULLET_PATH=DIR'}

    def build() -> tuple[int, int]:
        client = pybullet.connect(pybullet.DIRECT)
        pybullet.setTimeStep(STEP, physicsClientId=client)
        pybullet.setGravity(0, 0, -9.81, physicsClientId=client)
        plane = pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=client)
        pybullet.createMultiBody(0, plane, physicsClientId=client)
        wall = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.05, 2, 0.5],
                                             physicsClientId=client)
        pybullet.createMultiBody(0, wall, basePosition=[2, 0, 0.5], physicsClientId=client)
        robot = pybullet.loadURDF(str(urdf), [0, 0, 0.06], physicsClientId=client)
        return client, robot

    def drive(client: int, robot: int, left: float, right: float) -> None:
        pybullet.setJointMotorControlArray(robot, [0, 1], pybullet.VELOCITY_CONTROL,
                                           targetVelocities=[left, right], forces=[5.0, 5.0],
                                           physicsClientId=client)

    client, robot = build()
    drive(client, robot, 10.0, 10.0)
    steps = _rate(lambda: pybullet.stepSimulation(physicsClientId=client))
    position = pybullet.getBasePositionAndOrientation(robot, physicsClientId=client)[0]
    if not all(math.isfinite(v) for v in position) or abs(position[0]) < 0.5:
        raise RuntimeError(f'PyBullet run diverged or did not drive: {position}')
    starts = [(0.0, 0.0, 0.2)] * BEAMS
    ends = [(12 * x, 12 * y, 0.2) for x, y, _ in _directions()]
    scans = _rate(lambda: pybullet.rayTestBatch(starts, ends, physicsClientId=client))
    pybullet.disconnect(client)

    def trajectory() -> tuple[object, ...]:
        c, r = build()
        for i in range(2000):
            drive(c, r, 10.0, 6.0 + (i % 7))
            pybullet.stepSimulation(physicsClientId=c)
        state = pybullet.getBasePositionAndOrientation(r, physicsClientId=c)
        pybullet.disconnect(c)
        return tuple(state)

    loads = {}
    for path in sorted(TUTORIAL.glob('0[1-7]*.urdf')):
        c = pybullet.connect(pybullet.DIRECT)
        try:
            body = pybullet.loadURDF(str(path), physicsClientId=c)
            loads[path.name[:2]] = f'{pybullet.getNumJoints(body, physicsClientId=c) + 1} links'
        except Exception as error:
            loads[path.name[:2]] = 'refused: ' + str(error)[:60]
        pybullet.disconnect(c)
    return {'steps/s': steps, 'scans/s': scans, 'deterministic': trajectory() == trajectory(),
            'urdf_tutorial': loads}


@contextlib.contextmanager
def _quiet_output() -> Iterator[None]:
    sys.stdout.flush()
    saved = [os.dup(1), os.dup(2)]
    with open(os.devnull, 'w') as null:
        os.dup2(null.fileno(), 1)
        os.dup2(null.fileno(), 2)
    try:
        yield
    finally:
        for fd, copy in ((1, saved[0]), (2, saved[1])):
            os.dup2(copy, fd)
            os.close(copy)


def _headless_speed() -> float:
    from robot_lab.sim.sample_robot import WHEEL_RADIUS
    from robot_lab.sim.simulation import Simulation

    sim = Simulation('room.sdf', warn=print)
    sim.spawn(diffbot_urdf(), 'diffbot', (0.0, 0.0, WHEEL_RADIUS + 0.001))
    sim.command('/cmd_vel', {'linear': {'x': 0.2}, 'angular': {'z': 0.3}})
    start, steps = time.perf_counter(), 5000
    sim.step(steps)
    return steps * sim.info.step / (time.perf_counter() - start)


def _program(package: str, name: str) -> list[str]:
    return [str(Path(sys.prefix) / 'lib' / package / name)]


STAGES = (('sim serving', 'sim', 'Serving partition'), ('spawned', 'create', 'successful'),
          ('bridge node', 'bridge', 'Creating GZ->ROS'))


def _watch(process: Any, name: str, begin: float, marks: dict[str, float]) -> None:
    """Note when each process first says what marks a stage (its own log lines)."""
    for line in process.stdout:
        for stage, who, text in STAGES:
            if who == name and text in line and stage not in marks:
                marks[stage] = time.monotonic() - begin


def _real_time(seconds: float, urdf: Path) -> tuple[dict[str, float], dict[str, float]]:
    """(real-time factors and % of a core, the start's stages in s) of the processes a lab
    starts: as a launch file does, the simulator, `create`, the bridge and a subscriber
    (this process) all start at once."""
    import subprocess
    import threading

    import psutil
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan

    from robot_lab.sim.transport import connect

    marks: dict[str, float] = {}
    begin = time.monotonic()

    def start(*argv: str) -> subprocess.Popen[str]:
        return subprocess.Popen(list(argv), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True)

    sim = start(*_program('ros_gz_sim', 'gz_sim'), '-r', 'room.sdf')
    bridge = start(*_program('ros_gz_bridge', 'parameter_bridge'),
                   '/scan@sensor_msgs/msg/LaserScan[gz.msgs.LaserScan')
    create = start(*_program('ros_gz_sim', 'create'), '-file', str(urdf), '-name', 'bot',
                   '-z', '0.051')
    for child, name in ((sim, 'sim'), (bridge, 'bridge'), (create, 'create')):
        threading.Thread(target=_watch, args=(child, name, begin, marks), daemon=True).start()
    try:
        rclpy.init()
        node = rclpy.create_node('bench_sim')
        first: list[float] = []
        node.create_subscription(LaserScan, '/scan', lambda _: first.append(time.monotonic()),
                                 qos_profile_sensor_data)
        marks['subscriber'] = time.monotonic() - begin
        while not first:
            rclpy.spin_once(node, timeout_sec=0.05)
            if 'publisher seen' not in marks and node.count_publishers('/scan'):
                marks['publisher seen'] = time.monotonic() - begin
            if time.monotonic() - begin > 60:
                raise RuntimeError('no /scan within 60 s of starting the simulator')
        marks['first /scan'] = first[0] - begin
        node.destroy_node()
        rclpy.shutdown()
        if create.wait() != 0:
            raise RuntimeError('create failed')
        connection = connect()
        assert connection is not None
        connection.send({'op': 'sub', 'topic': '/world/room/stats'})

        def stats() -> tuple[float, float, float, float]:
            """(wall s here on receipt, sim_time s, real_time s, real_time_factor)"""
            frame = connection.receive()
            assert frame is not None
            msg = frame['msg']
            return (time.monotonic(), msg['sim_time']['sec'] + msg['sim_time']['nsec'] * 1e-9,
                    msg['real_time']['sec'] + msg['real_time']['nsec'] * 1e-9,
                    float(msg['real_time_factor']))

        process = psutil.Process(sim.pid)
        origin, cpu0 = stats(), process.cpu_times()
        factors = []
        while (last := stats())[0] - origin[0] < seconds:
            factors.append(last[3])
        cpu1 = process.cpu_times()
        connection.close()
        wall = last[0] - origin[0]
        cpu = (cpu1.user + cpu1.system - cpu0.user - cpu0.system) / wall * 100
        # as Gazebo reports it: the server's own sim_time over its own real_time, and the
        # mean of its real_time_factor fields; beside it, sim time over this process's clock
        # (what the bench measured before: receipt delay at either end biases it)
        return {'stats': (last[1] - origin[1]) / (last[2] - origin[2]),
                'fields': statistics.fmean(factors), 'received': (last[1] - origin[1]) / wall,
                'cpu': cpu}, marks
    finally:
        from robot_lab.process import stop

        for proc in (bridge, sim):  # Ctrl-C, then SIGTERM, then SIGKILL: a hung one ends
            stop(proc)


def system(runs: int, busy: int, seconds: float) -> None:
    sys.path.insert(0, str(REPO / 'bench'))
    from busy import busy_loops

    from robot_lab.env import apply_ros_defaults

    apply_ros_defaults()  # the environment `ros2 run` gives: the kit's Fast DDS profile

    speeds = [_headless_speed() for _ in range(runs)]
    print(f'headless maximum speed: {statistics.median(speeds):.1f}x real time '
          f'(goal >= 20x), median of {runs}')
    with tempfile.TemporaryDirectory() as folder, busy_loops(busy):
        urdf = Path(folder) / 'diffbot.urdf'
        urdf.write_text(diffbot_urdf(samples=BEAMS))
        results = [_real_time(seconds, urdf) for _ in range(runs)]
    figures = {key: statistics.median(r[0][key] for r in results) for key in results[0][0]}
    stages = {name: statistics.median(r[1].get(name, math.nan) for r in results)
              for name in results[0][1]}
    print(f'beside {busy} busy loops: real-time factor {figures["stats"]:.4f} (goal >= 1.0; '
          f'/world/room/stats sim_time over real_time; its real_time_factor fields average '
          f'{figures["fields"]:.4f}; sim time over this process\'s clock '
          f'{figures["received"]:.4f}), simulator CPU {figures["cpu"]:.1f} % of a core '
          f'(goal <= 25 %), start to first /scan {stages["first /scan"]:.2f} s (goal <= 3 s), '
          f'median of {runs} runs of {seconds:g} s')
    print('  real-time factor of each run (stats): ' + ', '.join(
        f'{r[0]["stats"]:.4f}' for r in results))
    print('  the start, s after launching (medians): ' + ', '.join(
        f'{name} {value:.2f}' for name, value in sorted(stages.items(), key=lambda i: i[1])))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=5)
    parser.add_argument('--system', action='store_true', help="the kit's simulator itself")
    parser.add_argument('--busy', type=int, default=1, help='busy loops beside it (a kernel)')
    parser.add_argument('--seconds', type=float, default=5.0)
    args = parser.parse_args()
    if args.system:
        system(args.runs, args.busy, args.seconds)
        return
    with tempfile.TemporaryDirectory() as folder:
        urdf = Path(folder) / 'diffbot.urdf'
        urdf.write_text(diffbot_urdf(samples=BEAMS))
        for name, bench in (('MuJoCo', bench_mujoco), ('PyBullet', bench_pybullet)):
            with _quiet_output():  # PyBullet prints a warning per link without inertia
                results = [bench(urdf) for _ in range(args.runs)]
            if 'missing' in results[0]:
                print(f'{name}: not installed ({results[0]["missing"]})')
                continue
            steps = statistics.median(float(str(r['steps/s'])) for r in results)
            scans = statistics.median(float(str(r['scans/s'])) for r in results)
            same = all(r['deterministic'] for r in results)
            print(f'{name}: {steps / 1000:.1f}k steps/s (goal: 20x real time at 1 ms = 20k), '
                  f'{scans / 1000:.2f}k {BEAMS}-beam scans/s (a 10 Hz lidar needs 10), '
                  f'deterministic {same}')
            print(f'  urdf_tutorial: {results[0]["urdf_tutorial"]}')


if __name__ == '__main__':
    main()
