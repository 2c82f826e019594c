"""Which joints a joint state publisher (or its sliders) sets, their ranges and zeros.

As joint_state_publisher reads a URDF: every joint but fixed, floating and planar ones,
in document order; a continuous joint ranges over ±π; a revolute or prismatic one over
its <limit>, narrowed by <safety_controller> soft limits (`use_smallest_joint_limits`);
its start is `zeros[name]`, else 0, else the middle of a range that excludes 0. A joint
with <mimic> (`use_mimic_tags`) is not set: it follows its leader × multiplier + offset.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from robot_lab.urdf.model import Robot

__all__ = ['Dependent', 'FreeJoint', 'JointTable', 'joint_table']


@dataclass
class FreeJoint:
    name: str
    lower: float
    upper: float
    zero: float
    continuous: bool
    position: float
    forward: bool = True  # the direction `delta` sweeps it


@dataclass(frozen=True)
class Dependent:
    parent: str
    factor: float = 1.0
    offset: float = 0.0


@dataclass
class JointTable:
    """The published joints: `order` (document order), the free ones and the followers."""

    order: list[str]
    free: dict[str, FreeJoint]
    dependent: dict[str, Dependent]

    def positions(self) -> list[float]:
        """Each joint of `order`'s position; followers through their (chained) leaders."""
        return [self.position(name) for name in self.order]

    def position(self, name: str) -> float:
        if name in self.free:
            return self.free[name].position
        factor, offset, seen = 1.0, 0.0, [name]
        link = self.dependent[name]
        while True:
            offset += factor * link.offset
            factor *= link.factor
            if link.parent in self.free:
                return self.free[link.parent].position * factor + offset
            if link.parent in seen or link.parent not in self.dependent:
                raise ValueError('Found an infinite recursive mimic chain: '
                                 f'{[*seen, link.parent]}')
            seen.append(link.parent)
            link = self.dependent[link.parent]


def joint_table(robot: Robot, zeros: Mapping[str, float] | None = None,
                use_mimic_tags: bool = True, use_smallest_joint_limits: bool = True,
                dependent: Mapping[str, Dependent] | None = None) -> JointTable:
    """The joints of `robot` a publisher sets, as joint_state_publisher chooses them."""
    zeros = zeros or {}
    table = JointTable([], {}, dict(dependent or {}))
    for joint in robot.joints.values():
        if not joint.moves:
            continue
        if joint.type == 'continuous':
            lower, upper = -math.pi, math.pi
        else:
            assert joint.limit is not None  # the model refuses a revolute joint without one
            lower, upper = joint.limit.lower, joint.limit.upper
        soft_lower, soft_upper = joint.soft_limits
        if use_smallest_joint_limits:
            lower = lower if soft_lower is None else max(lower, soft_lower)
            upper = upper if soft_upper is None else min(upper, soft_upper)
        table.order.append(joint.name)
        if use_mimic_tags and joint.mimic is not None:
            table.dependent[joint.name] = Dependent(joint.mimic.joint, joint.mimic.multiplier,
                                                    joint.mimic.offset)
            continue
        if joint.name in table.dependent:
            continue
        if joint.name in zeros:
            zero = float(zeros[joint.name])
        elif lower > 0 or upper < 0:
            zero = (lower + upper) / 2
        else:
            zero = 0.0
        table.free[joint.name] = FreeJoint(joint.name, lower, upper, zero,
                                           joint.type == 'continuous', zero)
    return table
