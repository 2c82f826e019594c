"""An SDF model with joints, plugins or sensors, read as a robot: Gazebo's own vehicles.

Gazebo's example worlds (the Jazzy tutorial's `visualize_lidar.sdf`: `vehicle_blue` with a
DiffDrive and a gpu_lidar) and `create -file robot.sdf` describe robots in SDF, not URDF.
The kit simulates robots from URDF (`robot`), so such a model is rewritten as the same
robot in URDF's shape: each link at its pose in the model, each joint's origin the child's
pose seen from the parent, the model's `<plugin>`s and each link's `<sensor>`s and surface
friction as `<gazebo>` blocks. The rewritten tree keeps every element's SDF file and line,
so each warning `robot` and `gazebo_tags` give still names the SDF. What URDF cannot say
(a ball joint, a joint pose off its child) is one line each.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from robot_lab.sim.xml_tree import Node, Warn, vector

__all__ = ['is_robot', 'sdf_robot']

_UNBOUNDED = 1e16  # SDF writes a continuous joint as limits of +-1.79769e+308
_LINK_KEEP = {'pose', 'inertial', 'collision', 'visual', 'sensor', 'self_collide',
              'enable_wind', 'gravity', 'kinematic', 'must_be_base_link'}


def is_robot(model: Node) -> bool:
    """A model gz-sim would drive or sense with: joints, plugins or sensors."""
    return bool(model.findall('joint') or model.findall('plugin')
                or any(link.findall('sensor') for link in model.findall('link')))


def _matrix(values: list[float]) -> np.ndarray:
    x, y, z, roll, pitch, yaw = values
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch),
                              math.sin(pitch), math.cos(yaw), math.sin(yaw))
    out = np.eye(4)
    out[:3, :3] = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                   [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                   [-sp, cp * sr, cp * cr]]
    out[:3, 3] = [x, y, z]
    return out


def _xyz_rpy(matrix: np.ndarray) -> tuple[str, str]:
    r = matrix[:3, :3]
    pitch = math.asin(max(-1.0, min(1.0, -float(r[2, 0]))))
    roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
    yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    return (' '.join(f'{v:.9g}' for v in matrix[:3, 3]),
            ' '.join(f'{v:.9g}' for v in (roll, pitch, yaw)))


def _node(tag: str, like: Node, children: list[Node] | None = None, text: str = '',
          attrib: dict[str, str] | None = None, **more: str) -> Node:
    """A URDF-shaped element that keeps the SDF element's file and line."""
    node = Node(tag, {**(attrib or {}), **more}, like.line, like.source, text)
    node.children = children or []
    return node


def _origin(like: Node, pose: Node | None) -> Node:
    xyz, rpy = _xyz_rpy(_matrix(vector(pose, 6)))
    return _node('origin', pose or like, xyz=xyz, rpy=rpy)


def _geometry(collision: Node, warn: Warn) -> Node | None:
    geometry = collision.find('geometry')
    for shape in geometry.children if geometry is not None else []:
        if shape.tag == 'box':
            return _node('box', shape, size=' '.join(f'{v:g}' for v in vector(
                shape.find('size'), 3, 1.0)))
        if shape.tag == 'cylinder':
            return _node('cylinder', shape, radius=f"{shape.number('radius', 0.5):g}",
                         length=f"{shape.number('length', 1.0):g}")
        if shape.tag == 'sphere':
            return _node('sphere', shape, radius=f"{shape.number('radius', 0.5):g}")
        if shape.tag == 'mesh':
            return _node('mesh', shape, filename=shape.value('uri'), scale=' '.join(
                f'{v:g}' for v in vector(shape.find('scale'), 3, 1.0)))
        warn(f"{shape.where}: <{shape.tag}> geometry on a robot link is not supported by "
             f"robot_lab's simulator; this collision is left out")
    return None


def _link(link: Node, warn: Warn) -> tuple[Node, list[Node]]:
    """The URDF <link>, and what goes in its `<gazebo reference>` block."""
    name = link.attrib.get('name', 'link')
    children: list[Node] = []
    inertial = link.find('inertial')
    if inertial is not None:
        inertia = inertial.find('inertia')
        values = {k: f"{inertia.number(k, 1.0 if k in ('ixx', 'iyy', 'izz') else 0.0):g}"
                  if inertia is not None else ('1' if k in ('ixx', 'iyy', 'izz') else '0')
                  for k in ('ixx', 'iyy', 'izz', 'ixy', 'ixz', 'iyz')}
        children.append(_node('inertial', inertial, [
            _origin(inertial, inertial.find('pose')),
            _node('mass', inertial, value=f"{inertial.number('mass', 1.0):g}"),
            _node('inertia', inertia or inertial, attrib=values)]))
    gazebo: list[Node] = []
    for index, collision in enumerate(link.findall('collision')):
        shape = _geometry(collision, warn)
        if shape is not None:
            children.append(_node('collision', collision, [
                _origin(collision, collision.find('pose')), _node('geometry', collision, [shape])],
                name=collision.attrib.get('name', f'collision{index}')))
        surface = collision.find('surface')
        friction = surface.find('friction') if surface is not None else None
        ode = friction.find('ode') if friction is not None else None
        if ode is not None and ode.find('mu') is not None:
            mu = ode.find('mu')
            assert mu is not None
            gazebo += [_node('mu1', mu, text=mu.text), _node('mu2', mu, text=mu.text)]
    gazebo += link.findall('sensor')
    for child in link.children:
        if child.tag not in _LINK_KEEP:
            warn(f"{child.where}: <{child.tag}> in <link> is not supported by robot_lab's "
                 f'simulator; ignored')
    return _node('link', link, children, name=name), gazebo


def _joint(joint: Node, poses: dict[str, np.ndarray], warn: Warn) -> Node:
    name, kind = joint.attrib.get('name', 'joint'), joint.attrib.get('type', 'fixed')
    parent, child = joint.value('parent'), joint.value('child')
    if any(vector(joint.find('pose'), 6)):
        warn(f"{joint.where}: joint {name!r} has a <pose> off its child link: robot_lab's "
             f"simulator puts the joint at the child link's origin")
    origin = np.linalg.inv(poses.get(parent, np.eye(4))) @ poses.get(child, np.eye(4))
    xyz, rpy = _xyz_rpy(origin)
    children = [_node('parent', joint, link=parent), _node('child', joint, link=child),
                _node('origin', joint, xyz=xyz, rpy=rpy)]
    axis = joint.find('axis')
    if kind == 'ball':
        warn(f"{joint.where}: ball joint {name!r} is not supported by robot_lab's simulator; "
             f'its child is fixed and frictionless (a caster)')
        kind = 'fixed'
    if kind in ('revolute', 'continuous', 'prismatic') and axis is not None:
        direction = np.array(vector(axis.find('xyz'), 3), dtype=float)
        xyz_node = axis.find('xyz')
        in_model = axis.value('use_parent_model_frame') in ('1', 'true') or (
            xyz_node is not None and xyz_node.attrib.get('expressed_in') == '__model__')
        if in_model:  # into the joint (= child link) frame, as URDF writes an axis
            direction = poses.get(child, np.eye(4))[:3, :3].T @ direction
        children.append(_node('axis', axis, xyz=' '.join(f'{v:.9g}' for v in direction)))
        limit = axis.find('limit')
        low = limit.number('lower', -math.inf) if limit is not None else -math.inf
        high = limit.number('upper', math.inf) if limit is not None else math.inf
        if kind == 'revolute' and (abs(low) >= _UNBOUNDED or abs(high) >= _UNBOUNDED):
            kind = 'continuous'
        if kind != 'continuous':
            effort = limit.number('effort', 0.0) if limit is not None else 0.0
            velocity = limit.number('velocity', 0.0) if limit is not None else 0.0
            children.append(_node('limit', limit or axis, lower=f'{low:g}', upper=f'{high:g}',
                                  effort=f'{max(effort, 0.0):g}',
                                  velocity=f'{max(velocity, 0.0):g}'))
    elif kind not in ('revolute', 'continuous', 'prismatic', 'fixed'):
        warn(f"{joint.where}: joint {name!r} of type {kind!r} is not supported by robot_lab's "
             f'simulator; simulated as fixed')
        kind = 'fixed'
    return _node('joint', joint, children, name=name, type=kind)


Vec3 = tuple[float, float, float]


def sdf_robot(model: Node, warn: Warn, xyz: Vec3, rpy: Vec3) -> tuple[str, Node, Vec3, Vec3]:
    """(URDF text, its element tree with the SDF's lines, and the pose to spawn it at) of
    an SDF robot model placed at xyz/rpy: a URDF's root link is the robot's own frame, so
    the SDF root link's pose in its model moves into the spawn pose."""
    name = model.attrib.get('name', 'robot')
    links = model.findall('link')
    poses = {link.attrib.get('name', 'link'): _matrix(vector(link.find('pose'), 6))
             for link in links}
    children: list[Node] = []
    joined = {j.value('child') for j in model.findall('joint')}
    roots = [n for n in poses if n not in joined]
    for link in links:
        node, gazebo = _link(link, warn)
        children.append(node)
        if gazebo:
            children.append(_node('gazebo', link, gazebo, reference=node.attrib['name']))
    for joint in model.findall('joint'):
        children.append(_joint(joint, poses, warn))
        if joint.attrib.get('type') == 'ball':
            zero = _node('mu1', joint, text='0')
            children.append(_node('gazebo', joint, [zero, _node('mu2', joint, text='0')],
                                  reference=joint.value('child')))
    static = model.value('static', 'false').lower() in ('1', 'true')
    if static or any(j.value('parent') == 'world' for j in model.findall('joint')):
        children.append(_node('link', model, name='world'))
        for top in roots if static else []:
            top_xyz, top_rpy = _xyz_rpy(poses[top])
            children.append(_node('joint', model, [
                _node('parent', model, link='world'), _node('child', model, link=top),
                _node('origin', model, xyz=top_xyz, rpy=top_rpy)],
                name=f'{top}_fixed_to_world', type='fixed'))
        base = np.eye(4)  # the world link is the model's frame
    else:
        base = poses[roots[0]] if roots else np.eye(4)
    if not static and len(roots) > 1 and 'world' not in {
            j.value('parent') for j in model.findall('joint')}:
        for extra in roots[1:]:
            warn(f"{model.where}: link {extra!r} of model {name!r} is joined to no other: "
                 f"robot_lab's simulator builds one tree per model; it is fixed to {roots[0]!r}")
            children.append(_node('joint', model, [
                _node('parent', model, link=roots[0]), _node('child', model, link=extra),
                _node('origin', model, xyz=_xyz_rpy(np.linalg.inv(poses[roots[0]])
                                                    @ poses[extra])[0],
                      rpy=_xyz_rpy(np.linalg.inv(poses[roots[0]]) @ poses[extra])[1])],
                name=f'{extra}_fixed', type='fixed'))
    for plugin in model.findall('plugin'):
        children.append(_node('gazebo', plugin, [plugin]))
    for child in model.children:
        if child.tag not in ('link', 'joint', 'plugin', 'pose', 'static', 'self_collide',
                             'allow_auto_disable', 'enable_wind'):
            warn(f"{child.where}: <{child.tag}> in a robot <model> is not supported by "
                 f"robot_lab's simulator; ignored")
    root = _node('robot', model, children, name=name)
    spawn = _matrix([*xyz, *rpy]) @ base
    at_xyz, at_rpy = (tuple(float(v) for v in text.split()) for text in _xyz_rpy(spawn))
    return _xml(root), root, (at_xyz[0], at_xyz[1], at_xyz[2]), (at_rpy[0], at_rpy[1], at_rpy[2])


def _xml(node: Node) -> str:
    attributes = ''.join(f' {k}={quoteattr(v)}' for k, v in node.attrib.items())
    inner = escape(node.text) + ''.join(_xml(child) for child in node.children)
    return f'<{node.tag}{attributes}>{inner}</{node.tag}>' if inner else \
        f'<{node.tag}{attributes}/>'
