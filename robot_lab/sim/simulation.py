"""One simulated world: MuJoCo's model and data, the robots spawned in it, their systems.

This is gz-sim's server without its transport: `step()` advances the physics by the
world's fixed step and runs the systems; `spawn()` is the create service; what systems
publish goes to `on_publish`, and `command()` delivers a message to a system's
subscription, the way a gz topic would. Time is an integer count of nanoseconds
(steps x step), so the same world, commands and seed give the same trajectory.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.sim import engine_log
from robot_lab.sim.imu import Imu
from robot_lab.sim.joint_controller import JointPositionController
from robot_lab.sim.robot import SpawnedRobot, add_robot
from robot_lab.sim.systems import (
    DiffDrive,
    JointStatePublisher,
    Lidar,
    Publish,
    System,
    header,
)
from robot_lab.sim.transport import topic_name
from robot_lab.sim.world import WorldInfo, add_model, find_world, load_world
from robot_lab.sim.xml_tree import Node, Warn

__all__ = ['CLOCK_RATE', 'Simulation']

Message = dict[str, Any]
CLOCK_RATE = 100.0  # /clock messages per simulated second (Gazebo throttles its own too)


def _print_warning(line: str) -> None:
    print(f'[Wrn] {line}', flush=True)


class Simulation:
    """A world file loaded and ready to step; robots join it with `spawn`."""

    def __init__(self, world: str | Path, *, warn: Warn = _print_warning, seed: int = 0,
                 on_publish: Publish | None = None) -> None:
        self.warn = warn
        self.path = find_world(str(world))
        self.spec, self.info = load_world(self.path, warn)
        self.speaker = f'world {self.info.name!r} ({self.path.name})'
        self._speak()
        self.model = self.spec.compile()
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        self.rng = random.Random(seed)
        self.steps = 0
        self.step_ns = round(self.info.step * 1e9)
        self.robots: dict[str, SpawnedRobot] = {}
        self.systems: list[System] = []
        self.subscriptions: dict[str, list[Callable[[Message], None]]] = {}
        self.on_publish: Publish = on_publish or (lambda topic, kind, message: None)
        self.clock_period = round(1e9 / CLOCK_RATE)
        while self.info.robots:  # the world's SDF robots (vehicle_blue): as spawned
            robot = self.info.robots.pop(0)
            self.spawn(robot.urdf, robot.name, robot.xyz, robot.rpy, robot.source, robot.root)

    def _speak(self) -> None:
        """MuJoCo's warnings from the calls that follow name this world (see engine_log)."""
        engine_log.speak_for(self.speaker, self.warn)

    @property
    def world(self) -> WorldInfo:
        return self.info

    @property
    def time_ns(self) -> int:
        return self.steps * self.step_ns

    def subscribe(self, topic: str, callback: Callable[[Message], None]) -> None:
        self.subscriptions.setdefault(topic_name(topic), []).append(callback)

    def command(self, topic: str, message: Message) -> bool:
        """Deliver a message to the systems that take `topic`; False if none does."""
        callbacks = self.subscriptions.get(topic_name(topic), [])
        for callback in callbacks:
            callback(message)
        return bool(callbacks)

    def spawn(self, urdf: str, name: str, xyz: tuple[float, float, float] = (0.0, 0.0, 0.0),
              rpy: tuple[float, float, float] = (0.0, 0.0, 0.0),
              source: str = 'robot_description', root: Node | None = None) -> SpawnedRobot:
        """`ros_gz_sim create`: the URDF's robot at a pose, its `<gazebo>` systems running
        (`root`: an SDF robot's tree, see `sdf_robot`)."""
        robot = add_robot(self.spec, urdf, name, source, xyz, rpy, self.warn, root)
        systems: list[System] = []
        for drive in robot.tags.diff_drives:
            missing = [j for j in drive.left_joints + drive.right_joints if j not in robot.joints]
            if missing:
                self.warn(f'{source}: DiffDrive names joint(s) {missing} that the robot has not '
                          f'(or that do not move); the system is not loaded')
                continue
            systems.append(DiffDrive(drive, robot, self.spec, self.subscribe))
        systems += [JointStatePublisher(j, robot, self.info.name)
                    for j in robot.tags.joint_states]
        for controller in robot.tags.joint_positions:
            if controller.joint not in robot.joints:
                self.warn(f'{source}: JointPositionController names joint '
                          f'{controller.joint!r}, which the robot has not (or which does not '
                          f'move); the system is not loaded')
                continue
            systems.append(JointPositionController(controller, robot, self.subscribe))
        systems += [Lidar(lidar, robot, self.info.name, self.rng) for lidar in robot.tags.lidars]
        systems += [Imu(imu, robot, self.info.name, self.spec, self.rng) for imu in robot.tags.imus]
        self._speak()
        self.model, self.data = self.spec.recompile(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        self.systems += systems
        for system in self.systems:
            system.bind(self.model)
        self.robots[name] = robot
        return robot

    def spawn_model(self, sdf: str, name: str = '',
                    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0),
                    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0),
                    source: str = '<string>') -> str:
        """`ros_gz_sim create` of an SDF model; one with joints, plugins or sensors is a
        robot (`sdf_robot`), spawned as a URDF one is."""
        name = add_model(self.spec, self.info, sdf, source, name, xyz, rpy, self.warn)
        if self.info.robots:  # it was a robot: add_model queued it
            robot = self.info.robots.pop()
            return self.spawn(robot.urdf, robot.name, robot.xyz, robot.rpy, robot.source,
                              robot.root).name
        self._speak()
        self.model, self.data = self.spec.recompile(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        for system in self.systems:
            system.bind(self.model)
        return name

    def step(self, count: int = 1) -> None:
        """Advance `count` fixed steps, running every system around each."""
        self._speak()
        for _ in range(count):
            time_ns = self.time_ns
            for system in self.systems:
                system.pre_update(self.model, self.data, time_ns)
            mujoco.mj_step(self.model, self.data)
            self.steps += 1
            time_ns = self.time_ns
            if any(system.senses(time_ns) for system in self.systems):
                mujoco.mj_forward(self.model, self.data)  # what sensors see: the new state
            for system in self.systems:
                system.post_update(self.model, self.data, time_ns, self.on_publish)
            if time_ns % self.clock_period == 0:
                self.publish_clock()

    def publish_clock(self) -> None:
        """gz.msgs.Clock at the current time on /clock and /world/<name>/clock (also while
        paused: the server repeats it, as Gazebo's loop does)."""
        time_ns = self.time_ns
        clock = {'header': header(time_ns), 'sim': {'sec': time_ns // 1_000_000_000,
                                                    'nsec': time_ns % 1_000_000_000}}
        self.on_publish('/clock', 'gz.msgs.Clock', clock)
        self.on_publish(f'/world/{self.info.name}/clock', 'gz.msgs.Clock', clock)

    def reset(self) -> None:
        """Gazebo's world reset: time 0, every body back at its spawn pose, systems afresh."""
        self._speak()
        mujoco.mj_resetData(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        self.steps = 0
        for system in self.systems:
            system.reset()

    def body_pose(self, robot: str) -> tuple[float, float, float]:
        """x, y and heading of a robot's root link in the world (for tests and views)."""
        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY,
                                 self.robots[robot].body(self.robots[robot].urdf.root))
        x, y = float(self.data.xpos[body][0]), float(self.data.xpos[body][1])
        matrix = self.data.xmat[body]
        return x, y, math.atan2(float(matrix[3]), float(matrix[0]))
