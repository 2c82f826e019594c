"""`check_urdf FILE`: urdfdom's check, with its output, and the kit's one-line errors.

urdfdom prints the robot's name, a success line, the root link and the link tree, each
link's children in the order of their joints' names (urdfdom keeps joints in a sorted
map). A URDF it refuses gets the kit's `file:line: what — fix: how`, then urdfdom's own
last line, and exit code 255, as urdfdom's -1.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from robot_lab.errors import UrdfError
from robot_lab.urdf.model import Robot, load_urdf

__all__ = ['check_urdf_lines', 'main', 'tree_lines']


def _children(robot: Robot, link: str) -> list[str]:
    return [j.child for j in sorted(robot.child_joints.get(link, []), key=lambda j: j.name)]


def tree_lines(robot: Robot, link: str | None = None, level: int = 0) -> list[str]:
    """urdfdom's printTree: `child(n):  name`, two spaces of indent per level, from 4."""
    level += 2
    lines: list[str] = []
    for count, child in enumerate(_children(robot, link or robot.root), 1):
        lines.append('  ' * level + f'child({count}):  {child}')
        lines.extend(tree_lines(robot, child, level))
    return lines


def check_urdf_lines(robot: Robot) -> list[str]:
    """What check_urdf prints for a URDF it accepts."""
    return [
        f'robot name is: {robot.name}',
        '---------- Successfully Parsed XML ---------------',
        f'root Link: {robot.root} has {len(_children(robot, robot.root))} child(ren)',
        *tree_lines(robot),
    ]


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 1:
        print('Usage: check_urdf <urdf_file>', file=sys.stderr)
        return 255
    path = args[0]
    try:
        with open(path, 'rb') as file:
            text = file.read()
    except OSError:
        print(f'Could not open file [{path}] for parsing.', file=sys.stderr)
        return 255
    try:
        if b'xmlns:xacro' in text or b'<xacro:' in text:  # urdfdom would choke on ${...}
            raise UrdfError('this is xacro, not URDF yet', file=path,
                            fix=f'expand it first: xacro {path} > model.urdf; '
                                'check_urdf model.urdf')
        robot = load_urdf(path)
    except UrdfError as err:
        print(f'Error:   {err}', file=sys.stderr)
        print('ERROR: Model Parsing the xml failed', file=sys.stderr)
        return 255
    print('\n'.join(check_urdf_lines(robot)))
    return 0


def entry() -> None:
    """The `check_urdf` console script."""
    sys.exit(main())


if __name__ == '__main__':
    entry()
