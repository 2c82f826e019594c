"""How a robot differs from the one a lesson or a rubric asks for.

The notebook's check (`grading.check.description.urdf_tree`) and the package grader's
(`grading.package.checks.description.urdf_describes`) ask the same questions of a parsed
URDF: are these links there, is this the root, does each link hang from this parent, is
each joint of this type. They word the answers for their own readers; the comparison is
here, once.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from robot_lab.urdf.model import Joint, Robot

__all__ = ['Difference', 'differences']


@dataclass(frozen=True)
class Difference:
    """One way the robot differs. `kind`:

    - `no_link`: link `name` is missing (`wanted`: the parent asked for it, else '');
    - `root`: the root link is `name`, not `wanted`;
    - `parent`: link `name` hangs from `joint.parent`, not `wanted` (`joint` None: it is
      the root, no joint carries it);
    - `no_joint`: joint `name` is missing;
    - `joint_type`: joint `name` is a `joint.type`, not a `wanted`.
    """

    kind: str
    name: str
    wanted: str = ''
    joint: Joint | None = None


def differences(robot: Robot, *, links: Iterable[str] = (),
                parents: Mapping[str, str] | None = None,
                joint_types: Mapping[str, str] | None = None,
                root: str = '') -> list[Difference]:
    """Every difference, in this order: missing links (`links`, then the children named
    in `parents`), the root, each link's parent, each joint's presence and type."""
    parents = parents or {}
    joint_types = joint_types or {}
    found: list[Difference] = []
    asked = dict.fromkeys(links, '')
    for child, parent in parents.items():
        asked.setdefault(child, parent)
    found += [Difference('no_link', name, wanted) for name, wanted in asked.items()
              if name not in robot.links]
    if root and robot.root != root:
        found.append(Difference('root', robot.root, root))
    for child, parent in parents.items():
        joint = robot.parent_joint(child)
        if child in robot.links and (joint is None or joint.parent != parent):
            found.append(Difference('parent', child, parent, joint))
    for name, kind in joint_types.items():
        joint = robot.joints.get(name)
        if joint is None:
            found.append(Difference('no_joint', name, kind))
        elif joint.type != kind:
            found.append(Difference('joint_type', name, kind, joint))
    return found
