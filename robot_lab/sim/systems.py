"""The systems a spawned robot's `<gazebo>` tags ask for: DiffDrive, JointStatePublisher, lidar.

Each runs as gz-sim runs a system: `pre_update` before a physics step (commands into the
joints), `post_update` after it (state out, at the system's own rate in simulated time).
Messages leave as dicts shaped like Gazebo's gz.msgs (field names as in the .proto files)
through `publish(topic, gz_type, message)`; commands arrive through `subscribe`. Time is
the simulation's integer nanoseconds, so rates land on exact steps and runs repeat exactly.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from typing import Any

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed
import numpy as np

from robot_lab.sim.gazebo_tags import DiffDriveSettings, JointStateSettings, LidarSettings
from robot_lab.sim.robot import SpawnedRobot
from robot_lab.sim.shapes import quat_from_rpy
from robot_lab.sim.transport import topic_name
from robot_lab.sim.wheels import round_wheel, wheel_torque

__all__ = ['DiffDrive', 'JointStatePublisher', 'Lidar', 'Publish', 'Subscribe', 'System',
           'stamp']

Message = dict[str, Any]
Publish = Callable[[str, str, Message], None]
Subscribe = Callable[[str, Callable[[Message], None]], None]
WHEEL_GAIN = 2.0  # N m per rad/s: the wheels' velocity servo (Gazebo commands velocity)


def stamp(time_ns: int) -> dict[str, int]:
    return {'sec': time_ns // 1_000_000_000, 'nsec': time_ns % 1_000_000_000}


def header(time_ns: int, frame: str = '') -> Message:
    return {'stamp': stamp(time_ns), 'frame_id': frame}


class System:
    """A system's interface; `period_ns` 0 means every step."""

    period_ns = 0

    def __init__(self) -> None:
        self.next_ns = 0

    def bind(self, model: mujoco.MjModel) -> None:
        """Look up ids again: spawning a robot recompiles the model."""

    def advertised(self) -> dict[str, str]:
        """Topic -> gz type of what it publishes: advertised from its start, as gz-sim's
        systems advertise in Configure (so `gz topic -l` lists them while paused)."""
        return {}

    def reset(self) -> None:
        """The world went back to time 0 (Gazebo's world reset): start over."""
        self.next_ns = 0

    def pre_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int) -> None:
        """Before the step."""

    def post_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int,
                    publish: Publish) -> None:
        """After the step, only when its period has come round (see `due`)."""

    def senses(self, time_ns: int) -> bool:
        """Whether this step's post_update reads the state a sensor sees (positions of every
        body, MuJoCo's sensors): mj_step leaves those as they were before its integration."""
        return False

    def pending(self, time_ns: int) -> bool:
        """Whether `due` will say yes at `time_ns` (without moving the period on): what a
        sensor's `senses` asks."""
        return time_ns >= (self.next_ns or self.period_ns)

    def due(self, time_ns: int) -> bool:
        """Whether a period has come round: at whole multiples of it in simulated time."""
        if self.next_ns == 0:
            self.next_ns = self.period_ns
        if time_ns < self.next_ns:
            return False
        self.next_ns = (time_ns // self.period_ns + 1) * self.period_ns if self.period_ns else 0
        return True


def _period(rate: float) -> int:
    return round(1e9 / rate) if rate > 0 else 0


class DiffDrive(System):
    """gz::sim::systems::DiffDrive: Twist in, wheel velocities, odometry from the wheels."""

    def __init__(self, settings: DiffDriveSettings, robot: SpawnedRobot,
                 spec: mujoco.MjSpec, subscribe: Subscribe) -> None:
        super().__init__()
        self.s = settings
        self.robot = robot
        self.period_ns = _period(settings.odom_publish_frequency)
        self.command = (0.0, 0.0)
        self.applied = (0.0, 0.0)
        self.written: tuple[float, float] | None = None
        self._distance = self._turn = 0.0  # since the last odometry message
        self.left = [robot.joints[j] for j in settings.left_joints]
        self.right = [robot.joints[j] for j in settings.right_joints]
        self.pose = [0.0, 0.0, 0.0]  # x, y, heading in the odometry frame
        self.wheels: tuple[float, float] | None = None
        self.last_ns = 0
        self.velocity = (0.0, 0.0)
        urdf_joints = settings.left_joints + settings.right_joints
        for joint, urdf_joint in zip(self.left + self.right, urdf_joints, strict=True):
            round_wheel(spec, robot, urdf_joint)
            torque = wheel_torque(spec, robot, urdf_joint, settings.wheel_radius,
                                  len(urdf_joints))
            actuator = spec.add_actuator()
            actuator.name = f'{joint}::velocity'
            actuator.target = joint
            actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
            actuator.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            actuator.gainprm = [WHEEL_GAIN] + [0.0] * 9
            actuator.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            actuator.biasprm = [0.0, 0.0, -WHEEL_GAIN] + [0.0] * 7
            actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            actuator.forcerange = [-torque, torque]
        name = robot.name
        self.cmd_topic = topic_name(settings.topic or f'/model/{name}/cmd_vel')
        self.odom_topic = topic_name(settings.odom_topic or f'/model/{name}/odometry')
        self.tf_topic = topic_name(settings.tf_topic or f'/model/{name}/tf')
        self.frame_id = settings.frame_id or f'{name}/odom'
        self.child_frame_id = settings.child_frame_id or f'{name}/{robot.urdf.root}'
        subscribe(self.cmd_topic, self.on_twist)

    def reset(self) -> None:
        super().reset()
        self.command = self.applied = (0.0, 0.0)
        self.written = None
        self.pose = [0.0, 0.0, 0.0]
        self.wheels = None
        self.last_ns = 0
        self.velocity = (0.0, 0.0)
        self._distance = self._turn = 0.0

    def on_twist(self, message: Message) -> None:
        s = self.s
        linear = float(message.get('linear', {}).get('x', 0.0))
        angular = float(message.get('angular', {}).get('z', 0.0))
        # the velocity limits at once; the acceleration limits step by step (pre_update)
        self.command = (min(max(linear, s.min_linear_velocity), s.max_linear_velocity),
                        min(max(angular, s.min_angular_velocity), s.max_angular_velocity))

    def advertised(self) -> dict[str, str]:
        return {self.odom_topic: 'gz.msgs.Odometry', self.tf_topic: 'gz.msgs.Pose_V'}

    def bind(self, model: mujoco.MjModel) -> None:
        self.actuators = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f'{j}::velocity')
                          for j in self.left + self.right]
        self.qpos = [model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)]
                     for j in self.left + self.right]
        self.written = None  # a new model: write the wheels again

    @staticmethod
    def _toward(value: float, previous: float, low: float, high: float, dt: float) -> float:
        return min(max(value, previous + low * dt), previous + high * dt)

    def pre_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int) -> None:
        if self.written == self.command:  # the wheels already turn as commanded
            return
        s, dt = self.s, float(model.opt.timestep)
        linear = self._toward(self.command[0], self.applied[0], s.min_linear_acceleration,
                              s.max_linear_acceleration, dt)
        angular = self._toward(self.command[1], self.applied[1], s.min_angular_acceleration,
                               s.max_angular_acceleration, dt)
        self.applied = (linear, angular)
        half = angular * s.wheel_separation / 2
        left, right = (linear - half) / s.wheel_radius, (linear + half) / s.wheel_radius
        count = len(self.left)
        for index, actuator in enumerate(self.actuators):
            data.ctrl[actuator] = left if index < count else right
        self.written = self.applied

    def _wheel_positions(self, data: mujoco.MjData) -> tuple[float, float]:
        count = len(self.left)
        lefts = [float(data.qpos[a]) for a in self.qpos[:count]]
        rights = [float(data.qpos[a]) for a in self.qpos[count:]]
        return sum(lefts) / len(lefts), sum(rights) / len(rights)

    def post_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int,
                    publish: Publish) -> None:
        left, right = self._wheel_positions(data)
        if self.wheels is None:
            self.wheels, self.last_ns = (left, right), time_ns
        r, sep = self.s.wheel_radius, self.s.wheel_separation
        d_left, d_right = (left - self.wheels[0]) * r, (right - self.wheels[1]) * r
        self.wheels = (left, right)
        distance, turn = (d_left + d_right) / 2, (d_right - d_left) / sep
        x, y, heading = self.pose
        if abs(turn) < 1e-9:  # second-order Runge-Kutta, as Gazebo's odometry integrates
            x += distance * math.cos(heading + turn / 2)
            y += distance * math.sin(heading + turn / 2)
        else:  # the exact arc
            radius = distance / turn
            x += radius * (math.sin(heading + turn) - math.sin(heading))
            y -= radius * (math.cos(heading + turn) - math.cos(heading))
        self.pose = [x, y, heading + turn]
        self._distance += distance
        self._turn += turn
        if not self.due(time_ns):
            return
        dt = (time_ns - self.last_ns) / 1e9
        if dt > 0:
            self.velocity = (self._distance / dt, self._turn / dt)
        self._distance = self._turn = 0.0
        self.last_ns = time_ns
        w, qx, qy, qz = quat_from_rpy(0.0, 0.0, self.pose[2])
        pose = {'position': {'x': x, 'y': y, 'z': 0.0},
                'orientation': {'x': qx, 'y': qy, 'z': qz, 'w': w}}
        publish(self.odom_topic, 'gz.msgs.Odometry', {
            'header': header(time_ns, self.frame_id), 'child_frame_id': self.child_frame_id,
            'pose': pose, 'twist': {'linear': {'x': self.velocity[0], 'y': 0.0, 'z': 0.0},
                                    'angular': {'x': 0.0, 'y': 0.0, 'z': self.velocity[1]}}})
        publish(self.tf_topic, 'gz.msgs.Pose_V', {'pose': [{
            'header': header(time_ns, self.frame_id), 'name': self.child_frame_id, **pose}]})


class JointStatePublisher(System):
    """gz::sim::systems::JointStatePublisher: the model's joints as gz.msgs.Model."""

    def __init__(self, settings: JointStateSettings, robot: SpawnedRobot, world: str,
                 rate: float = 50.0) -> None:
        super().__init__()
        self.names = settings.joints or list(robot.joints)
        self.mj_names = [robot.joints[n] for n in self.names if n in robot.joints]
        self.topic = topic_name(settings.topic or f'/world/{world}/model/{robot.name}/joint_state')
        self.model_name = robot.name
        self.period_ns = _period(rate)

    def advertised(self) -> dict[str, str]:
        return {self.topic: 'gz.msgs.Model'}

    def bind(self, model: mujoco.MjModel) -> None:
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in self.mj_names]
        self.addresses = [(model.jnt_qposadr[i], model.jnt_dofadr[i]) for i in ids]

    def post_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int,
                    publish: Publish) -> None:
        if not self.due(time_ns):
            return
        joints = [{'name': name, 'axis1': {'position': float(data.qpos[q]),
                                           'velocity': float(data.qvel[v]),
                                           'force': float(data.qfrc_actuator[v])}}
                  for name, (q, v) in zip(self.names, self.addresses, strict=True)]
        publish(self.topic, 'gz.msgs.Model', {'header': header(time_ns), 'name': self.model_name,
                                              'joint': joints})


class Lidar(System):
    """A `gpu_lidar`/`lidar` sensor: one ray per sample in the link's plane, gz.msgs.LaserScan."""

    def __init__(self, settings: LidarSettings, robot: SpawnedRobot, world: str,
                 rng: random.Random) -> None:
        super().__init__()
        self.s = settings
        self.rng = rng
        self.body_name = robot.body(settings.link) if settings.link else robot.body(robot.urdf.root)
        link = settings.link or robot.urdf.root
        self.topic = topic_name(settings.topic or f'/world/{world}/model/{robot.name}/link/'
                                f'{link}/sensor/{settings.name}/scan')
        self.frame = settings.frame_id or f'{robot.name}::{link}::{settings.name}'
        self.period_ns = _period(settings.update_rate)
        count = settings.samples
        step = (settings.max_angle - settings.min_angle) / (count - 1) if count > 1 else 0.0
        self.step = step
        angles = settings.min_angle + step * np.arange(count)
        local = np.stack([np.cos(angles), np.sin(angles), np.zeros(count)], axis=1)
        # the sensor's own pose on the link
        w, x, y, z = quat_from_rpy(*settings.rpy)
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, np.array([w, x, y, z]))
        self.offset_rot = rotation.reshape(3, 3)
        self.offset_pos = np.array(settings.xyz)
        self.local = local @ self.offset_rot.T
        self.geomid = np.zeros(count, dtype=np.int32)
        self.dist = np.zeros(count, dtype=np.float64)

    def advertised(self) -> dict[str, str]:
        return {self.topic: 'gz.msgs.LaserScan'}

    def bind(self, model: mujoco.MjModel) -> None:
        self.body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, self.body_name)

    def senses(self, time_ns: int) -> bool:
        return self.pending(time_ns)

    def ranges(self, model: mujoco.MjModel, data: mujoco.MjData) -> list[float]:
        rotation = data.xmat[self.body].reshape(3, 3)
        origin = data.xpos[self.body] + rotation @ self.offset_pos
        directions = (self.local @ rotation.T).ravel()
        s = self.s
        mujoco.mj_multiRay(model, data, origin, directions, None, True, self.body, self.geomid,
                           self.dist, None, s.samples, s.range_max)
        result = []
        for value in self.dist.tolist():
            if value < 0 or value > s.range_max:
                result.append(math.inf)
            elif value < s.range_min:
                result.append(-math.inf)
            else:
                if s.noise_stddev > 0:
                    value += self.rng.gauss(s.noise_mean, s.noise_stddev)
                result.append(value)
        return result

    def post_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int,
                    publish: Publish) -> None:
        if not self.due(time_ns):
            return
        s = self.s
        ranges = self.ranges(model, data)
        publish(self.topic, 'gz.msgs.LaserScan', {
            'header': header(time_ns, self.frame), 'frame': self.frame,
            'angle_min': s.min_angle, 'angle_max': s.max_angle, 'angle_step': self.step,
            'range_min': s.range_min, 'range_max': s.range_max, 'count': s.samples,
            'vertical_count': 1, 'ranges': ranges, 'intensities': [0.0] * s.samples})
