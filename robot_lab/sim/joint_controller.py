"""gz::sim::systems::JointPositionController: hold a joint at the position last commanded.

Gazebo's system runs a PID on the joint's position error and applies its output as the
joint's force, clamped to [cmd_min, cmd_max], with the integral term kept in [i_min, i_max];
its target comes as gz.msgs.Double on the system's topic. The kit does the same with
MuJoCo's applied generalized force, once per step.
"""

from __future__ import annotations

from typing import Any

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.sim.gazebo_tags import JointPositionSettings
from robot_lab.sim.robot import SpawnedRobot
from robot_lab.sim.systems import Subscribe, System
from robot_lab.sim.transport import topic_name

__all__ = ['JointPositionController']


class JointPositionController(System):
    """A PID on one joint, its target from gz.msgs.Double."""

    def __init__(self, settings: JointPositionSettings, robot: SpawnedRobot,
                 subscribe: Subscribe) -> None:
        super().__init__()
        self.s = settings
        self.joint = robot.joints[settings.joint]
        self.target = settings.initial_position
        self.integral = 0.0
        self.topic = topic_name(settings.topic or
                                f'/model/{robot.name}/joint/{settings.joint}/0/cmd_pos')
        subscribe(self.topic, self.on_command)

    def on_command(self, message: dict[str, Any]) -> None:
        self.target = float(message.get('data', 0.0))

    def bind(self, model: mujoco.MjModel) -> None:
        joint = model.joint(self.joint)
        self.qpos, self.dof = int(joint.qposadr[0]), int(joint.dofadr[0])

    def reset(self) -> None:
        super().reset()
        self.target = self.s.initial_position
        self.integral = 0.0

    def pre_update(self, model: mujoco.MjModel, data: mujoco.MjData, time_ns: int) -> None:
        s, dt = self.s, float(model.opt.timestep)
        error = self.target - float(data.qpos[self.qpos])
        self.integral = min(max(self.integral + s.i_gain * error * dt, s.i_min), s.i_max)
        force = s.p_gain * error + self.integral - s.d_gain * float(data.qvel[self.dof])
        data.qfrc_applied[self.dof] = min(max(force + s.cmd_offset, s.cmd_min), s.cmd_max)
