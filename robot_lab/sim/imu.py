"""The `imu` sensor: orientation, angular velocity and proper acceleration, as gz.msgs.IMU.

Gazebo's IMU reports orientation in the world frame, angular velocity and linear
acceleration in the sensor's frame; at rest the acceleration is +g upward (what an
accelerometer feels), in free fall zero. MuJoCo measures exactly these at a site: the
kit adds a site at the sensor's pose on its link with a frame-quaternion, a gyro and an
accelerometer, and reads them after each step the sensor is due.
"""

from __future__ import annotations

import random

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.sim.gazebo_tags import ImuSettings
from robot_lab.sim.robot import SpawnedRobot
from robot_lab.sim.shapes import quat_from_rpy
from robot_lab.sim.systems import Publish, System, header
from robot_lab.sim.transport import topic_name

__all__ = ['Imu']

_READINGS = (('orientation', mujoco.mjtSensor.mjSENS_FRAMEQUAT),
             ('angular_velocity', mujoco.mjtSensor.mjSENS_GYRO),
             ('linear_acceleration', mujoco.mjtSensor.mjSENS_ACCELEROMETER))


class Imu(System):
    """An `imu` sensor of a spawned robot."""

    def __init__(self, settings: ImuSettings, robot: SpawnedRobot, world: str,
                 spec: mujoco.MjSpec, rng: random.Random) -> None:
        super().__init__()
        self.s = settings
        self.rng = rng
        link = settings.link or robot.urdf.root
        site_name = f'{robot.name}::{link}::{settings.name}'
        body = spec.body(robot.body(link))
        site = body.add_site()
        site.name = site_name
        site.pos = list(settings.xyz)
        site.quat = quat_from_rpy(*settings.rpy)
        self.sensors = [f'{site_name}::{reading}' for reading, _ in _READINGS]
        for (_, kind), name in zip(_READINGS, self.sensors, strict=True):
            sensor = spec.add_sensor()
            sensor.name = name
            sensor.type = kind
            sensor.objtype = mujoco.mjtObj.mjOBJ_SITE
            sensor.objname = site_name
        self.topic = topic_name(settings.topic or f'/world/{world}/model/{robot.name}/link/'
                                f'{link}/sensor/{settings.name}/imu')
        self.frame = settings.frame_id or f'{robot.name}::{link}::{settings.name}'
        self.period_ns = round(1e9 / settings.update_rate) if settings.update_rate > 0 else 0

    def advertised(self) -> dict[str, str]:
        return {self.topic: 'gz.msgs.IMU'}

    def bind(self, model: mujoco.MjModel) -> None:
        self.addresses = [int(model.sensor(name).adr[0]) for name in self.sensors]

    def senses(self, time_ns: int) -> bool:
        return self.pending(time_ns)

    def _vector(self, data: mujoco.MjData, address: int, quantity: str) -> dict[str, float]:
        values = {}
        for offset, axis in enumerate('xyz'):
            value = float(data.sensordata[address + offset])
            mean, stddev = self.s.noise.get(f'{quantity}.{axis}', (0.0, 0.0))
            if stddev > 0 or mean != 0:
                value += self.rng.gauss(mean, stddev)
            values[axis] = value
        return values

    def post_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int,
                    publish: Publish) -> None:
        if self.period_ns and not self.due(time_ns):
            return
        q, w, a = self.addresses
        quaternion = [float(data.sensordata[q + i]) for i in range(4)]
        publish(self.topic, 'gz.msgs.IMU', {
            'header': header(time_ns, self.frame), 'entity_name': self.frame,
            'orientation': dict(zip('wxyz', quaternion, strict=True)),
            'angular_velocity': self._vector(data, w, 'angular_velocity'),
            'linear_acceleration': self._vector(data, a, 'linear_acceleration')})
