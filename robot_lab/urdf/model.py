"""A URDF robot model: links, joints and their tree, read with each element's line.

urdfdom (C++) reads URDF for robot_state_publisher and check_urdf; PyPI has no wheel of
it. This reader keeps what the kinematics and the tools need (names, joint types, origins,
axes, limits, mimic tags) and refuses what urdfdom refuses, but each refusal names the
file and line of the element at fault and how to fix it, which urdfdom's messages do not.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.errors import UrdfError
from robot_lab.xml_lines import XmlElement, parse_xml_lines

__all__ = [
    'JOINT_TYPES',
    'Element',
    'Joint',
    'JointLimit',
    'Link',
    'Mimic',
    'Robot',
    'load_urdf',
    'parse_urdf',
    'parse_xml',
]

JOINT_TYPES = ('revolute', 'continuous', 'prismatic', 'fixed', 'floating', 'planar')
Vector = tuple[float, float, float]


Element = XmlElement  # a URDF keeps everything in attributes; the text is unused


def parse_xml(text: str | bytes, source: str = 'robot_description') -> Element:
    """The document's root element; malformed XML is a UrdfError at expat's line."""
    return parse_xml_lines(text, source, Element, UrdfError)


@dataclass(frozen=True)
class JointLimit:
    lower: float
    upper: float
    effort: float
    velocity: float


@dataclass(frozen=True)
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Link:
    name: str
    line: int


@dataclass(frozen=True)
class Joint:
    """A URDF joint; `axis` is unit length (KDL normalises it too)."""

    name: str
    type: str
    parent: str
    child: str
    xyz: Vector
    rpy: Vector
    axis: Vector
    limit: JointLimit | None
    mimic: Mimic | None
    line: int
    soft_limits: tuple[float | None, float | None] = (None, None)  # <safety_controller>

    @property
    def moves(self) -> bool:
        """Whether robot_state_publisher sends it on /tf (else /tf_static, or not at all)."""
        return self.type in ('revolute', 'continuous', 'prismatic')


@dataclass
class Robot:
    """A parsed URDF: its links and joints in document order, and its tree."""

    name: str
    links: dict[str, Link]
    joints: dict[str, Joint]
    source: str
    root: str = ''
    child_joints: dict[str, list[Joint]] = field(default_factory=dict)  # link -> joints

    def parent_joint(self, link: str) -> Joint | None:
        return next((j for j in self.joints.values() if j.child == link), None)

    def movable_joints(self) -> list[Joint]:
        """What joint_state_publisher gives a position: not fixed, floating or planar."""
        return [j for j in self.joints.values() if j.moves]


def _floats(element: Element, attribute: str, default: Vector, source: str,
            what: str) -> Vector:
    text = element.attrib.get(attribute)
    if text is None:
        return default
    parts = text.split()
    try:
        values = tuple(float(part) for part in parts)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise UrdfError(f'{what} {attribute}="{text}" is not three numbers', file=source,
                        line=element.line, fix=f'write {attribute}="0 0 0" (metres, radians)')
    return (values[0], values[1], values[2])


def _number(element: Element, attribute: str, default: float | None, source: str,
            what: str) -> float:
    text = element.attrib.get(attribute)
    if text is None:
        if default is None:
            raise UrdfError(f'{what} has no {attribute}', file=source, line=element.line,
                            fix=f'add {attribute}="..." to <{element.tag}>')
        return default
    try:
        return float(text)
    except ValueError:
        raise UrdfError(f'{what} {attribute}="{text}" is not a number', file=source,
                        line=element.line, fix=f'write a number, e.g. {attribute}="0.0"') from None


def _name(element: Element, source: str) -> str:
    name = element.attrib.get('name', '')
    if not name:
        raise UrdfError(f'a <{element.tag}> has no name', file=source, line=element.line,
                        fix=f'add name="..." to the <{element.tag}>')
    return name


def _joint(element: Element, source: str) -> Joint:
    name = _name(element, source)
    what = f"joint '{name}'"
    kind = element.attrib.get('type', '')
    if kind not in JOINT_TYPES:
        raise UrdfError(f'{what} has type "{kind}", which URDF does not know', file=source,
                        line=element.line, fix=f'use one of {", ".join(JOINT_TYPES)}')
    ends: dict[str, str] = {}
    for end in ('parent', 'child'):
        tag = element.find(end)
        if tag is None or not tag.attrib.get('link'):
            raise UrdfError(f'{what} has no <{end} link="..."/>', file=source,
                            line=element.line if tag is None else tag.line,
                            fix=f'name the {end} link: <{end} link="..."/>')
        ends[end] = tag.attrib['link']
    origin = element.find('origin')
    xyz = rpy = (0.0, 0.0, 0.0)
    if origin is not None:
        xyz = _floats(origin, 'xyz', xyz, source, f'{what} <origin>')
        rpy = _floats(origin, 'rpy', rpy, source, f'{what} <origin>')
    axis = (1.0, 0.0, 0.0)
    axis_tag = element.find('axis')
    if axis_tag is not None and kind not in ('fixed', 'floating'):
        axis = _floats(axis_tag, 'xyz', axis, source, f'{what} <axis>')
        norm = math.sqrt(sum(v * v for v in axis))
        if norm == 0.0:
            raise UrdfError(f'{what} has a zero axis', file=source, line=axis_tag.line,
                            fix='give the axis a direction, e.g. xyz="0 0 1"')
        axis = (axis[0] / norm, axis[1] / norm, axis[2] / norm)
    limit = None
    limit_tag = element.find('limit')
    if limit_tag is not None and kind in ('revolute', 'prismatic', 'continuous'):
        where = f'{what} <limit>'
        limit = JointLimit(
            lower=_number(limit_tag, 'lower', 0.0, source, where),
            upper=_number(limit_tag, 'upper', 0.0, source, where),
            effort=_number(limit_tag, 'effort', None, source, where),
            velocity=_number(limit_tag, 'velocity', None, source, where),
        )
    elif limit_tag is None and kind in ('revolute', 'prismatic'):
        raise UrdfError(
            f'{what} is {kind} but has no <limit> (urdfdom refuses it)', file=source,
            line=element.line,
            fix='add <limit lower="-1.57" upper="1.57" effort="10" velocity="1"/> inside '
                'it, or make it type="continuous" if it turns without end')
    mimic = None
    mimic_tag = element.find('mimic')
    if mimic_tag is not None:
        if not mimic_tag.attrib.get('joint'):
            raise UrdfError(f'{what} <mimic> names no joint', file=source, line=mimic_tag.line,
                            fix='write <mimic joint="the joint to follow"/>')
        mimic = Mimic(mimic_tag.attrib['joint'],
                      _number(mimic_tag, 'multiplier', 1.0, source, f'{what} <mimic>'),
                      _number(mimic_tag, 'offset', 0.0, source, f'{what} <mimic>'))
    soft: tuple[float | None, float | None] = (None, None)
    safety = element.find('safety_controller')
    if safety is not None:
        where = f'{what} <safety_controller>'
        soft = tuple(_number(safety, key, None, source, where) if key in safety.attrib
                     else None for key in ('soft_lower_limit', 'soft_upper_limit'))  # type: ignore[assignment]
    return Joint(name, kind, ends['parent'], ends['child'], xyz, rpy, axis, limit, mimic,
                 element.line, soft)


def _missing_link(joint: Joint, end: str, link: str, links: dict[str, Link],
                  source: str) -> UrdfError:
    other = joint.child if end == 'parent' else joint.parent
    close = sorted((name for name in links if name != other and (
                        _distance(name, link) <= max(2, len(link) // 3)
                        or name.startswith(link) or link.startswith(name))),
                   key=lambda name: _distance(name, link))[:1]
    hint = f"did you mean '{close[0]}'? " if close else ''
    return UrdfError(
        f"joint '{joint.name}' names {end} link '{link}', which no <link> defines",
        file=source, line=joint.line,
        fix=f'{hint}name an existing link, or add <link name="{link}"/>')


def _distance(a: str, b: str) -> int:
    """Edit distance, to suggest the link a misspelt name meant."""
    row = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        previous, row[0] = row[0], i
        for j, cb in enumerate(b, 1):
            previous, row[j] = row[j], min(row[j] + 1, row[j - 1] + 1, previous + (ca != cb))
    return row[-1]


def _build_tree(robot: Robot) -> None:
    source = robot.source
    parent_of: dict[str, Joint] = {}
    for joint in robot.joints.values():
        for end, link in (('parent', joint.parent), ('child', joint.child)):
            if link not in robot.links:
                raise _missing_link(joint, end, link, robot.links, source)
        if joint.parent == joint.child:
            raise UrdfError(f"joint '{joint.name}' joins link '{joint.child}' to itself",
                            file=source, line=joint.line, fix='name two different links')
        if joint.child in parent_of:
            first = parent_of[joint.child]
            raise UrdfError(
                f"link '{joint.child}' is the child of two joints: '{first.name}' "
                f"(line {first.line}) and '{joint.name}'", file=source, line=joint.line,
                fix='a link has one parent joint: give one of them another child link')
        parent_of[joint.child] = joint
        robot.child_joints.setdefault(joint.parent, []).append(joint)
    for joint in robot.joints.values():
        if joint.mimic is not None and joint.mimic.joint not in robot.joints:
            raise UrdfError(f"joint '{joint.name}' mimics joint '{joint.mimic.joint}', which "
                            'does not exist', file=source, line=joint.line,
                            fix='name an existing joint in <mimic joint="..."/>')
    roots = [name for name in robot.links if name not in parent_of]
    if not roots:
        raise UrdfError('no root link: every link has a parent joint, so the joints form a '
                        'loop', file=source, line=next(iter(robot.links.values())).line,
                        fix="one link (usually base_link) must be no joint's child")
    if len(roots) > 1:
        extra = robot.links[roots[1]]
        raise UrdfError(
            f"two root links: '{roots[0]}' and '{roots[1]}' (no joint connects "
            f"'{roots[1]}' to the tree)", file=source, line=extra.line,
            fix=f"add a joint whose child is '{roots[1]}', or check its parent's name")
    robot.root = roots[0]
    reached = {robot.root}
    stack = [robot.root]
    while stack:
        for joint in robot.child_joints.get(stack.pop(), []):
            reached.add(joint.child)
            stack.append(joint.child)
    if len(reached) != len(robot.links):
        loop = next(j for j in robot.joints.values() if j.child not in reached)
        raise UrdfError(f"joint '{loop.name}' closes a loop: its links are not reached from "
                        f"the root '{robot.root}'", file=source, line=loop.line,
                        fix='a URDF is a tree: remove one joint of the loop')


def parse_urdf(text: str | bytes, source: str = 'robot_description') -> Robot:
    """The robot of a URDF document; `source` names it in errors (a file, a parameter)."""
    root = parse_xml(text, source)
    if root.tag != 'robot':
        raise UrdfError(f'the root element is <{root.tag}>, not <robot>', file=source,
                        line=root.line, fix='wrap the links and joints in <robot name="...">')
    name = root.attrib.get('name', '')
    if not name:
        raise UrdfError('the <robot> has no name', file=source, line=root.line,
                        fix='write <robot name="my_robot">')
    links: dict[str, Link] = {}
    joints: dict[str, Joint] = {}
    for element in root.children:
        if element.tag == 'link':
            link = Link(_name(element, source), element.line)
            if link.name in links:
                raise UrdfError(f"link '{link.name}' is not unique (also line "
                                f'{links[link.name].line})', file=source, line=link.line,
                                fix='give each link its own name')
            links[link.name] = link
        elif element.tag == 'joint':
            joint = _joint(element, source)
            if joint.name in joints:
                raise UrdfError(f"joint '{joint.name}' is not unique (also line "
                                f'{joints[joint.name].line})', file=source, line=joint.line,
                                fix='give each joint its own name')
            joints[joint.name] = joint
    if not links:
        raise UrdfError('the robot has no links', file=source, line=root.line,
                        fix='add at least <link name="base_link"/>')
    robot = Robot(name, links, joints, source)
    _build_tree(robot)
    return robot


def load_urdf(path: str | Path) -> Robot:
    """The robot of a URDF file (not xacro: run `xacro` first)."""
    file = Path(path)
    try:
        data = file.read_bytes()
    except OSError as exc:
        raise UrdfError(f'cannot read the URDF: {exc.strerror}', file=file,
                        fix='check the path') from None
    return parse_urdf(data, str(file))
