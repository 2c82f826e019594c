"""A robot from its URDF into the simulation, with the fixes a URDF needs, each said aloud.

MuJoCo's own URDF loader drops links with only visuals, refuses moving links without
inertia and `package://` paths, and welds the root to the world. The kit reads the URDF
itself (the tree from `robot_lab.urdf.model`, the same the robot_state_publisher uses) and
builds one body per link, so each of those cases becomes a fix with a warning that names
the link, as Gazebo's sdformat warns when it converts a URDF:
- a moving link without `<inertial>`: 0.1 kg and 1e-4 kg m² about each axis;
- `package://pkg/...`: the package's share folder from the ament index;
- meshes (.stl, .obj, .dae) read by trimesh into MuJoCo meshes, when trimesh can read them;
- a root not attached to a `world` link gets a free joint, as Gazebo spawns a model.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.sim.gazebo_tags import GazeboTags, read_gazebo_tags
from robot_lab.sim.meshes import add_mesh, resolve_mesh
from robot_lab.sim.shapes import Shape, add_shape, quat_from_rpy
from robot_lab.sim.xml_tree import Node, SimulationError, Warn, parse, vector
from robot_lab.urdf.model import Robot, parse_urdf

__all__ = ['DEFAULT_INERTIA', 'DEFAULT_MASS', 'SpawnedRobot', 'add_robot']

DEFAULT_MASS = 0.1
DEFAULT_INERTIA = 1e-4


@dataclass
class SpawnedRobot:
    """A robot in the spec: its name, parsed tree, `<gazebo>` settings and body names."""

    name: str
    urdf: Robot
    tags: GazeboTags
    bodies: dict[str, str]  # link -> MuJoCo body name
    joints: dict[str, str]  # URDF joint -> MuJoCo joint name (moving joints)

    def body(self, link: str) -> str:
        return self.bodies[link]


def _attribute_vector(node: Node | None, attribute: str, count: int) -> list[float]:
    if node is None or attribute not in node.attrib:
        return [0.0] * count
    probe = Node(attribute, {}, node.line, node.source, node.attrib[attribute])
    return vector(probe, count)


def _origin(node: Node) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    origin = node.find('origin')
    xyz = _attribute_vector(origin, 'xyz', 3)
    rpy = _attribute_vector(origin, 'rpy', 3)
    return (xyz[0], xyz[1], xyz[2]), (rpy[0], rpy[1], rpy[2])


def _mesh(spec: mujoco.MjSpec, geometry: Node, link: str, warn: Warn,
          base: Path | None) -> str:
    mesh = geometry.find('mesh')
    assert mesh is not None
    path = resolve_mesh(mesh.attrib.get('filename', ''), mesh, warn, base=base)
    if path is None:
        return ''
    scale = _attribute_vector(mesh, 'scale', 3) if 'scale' in mesh.attrib else [1.0] * 3
    return add_mesh(spec, path, scale, f'link {link!r}', mesh, warn)


def _collision_shape(spec: mujoco.MjSpec, collision: Node, link: str, warn: Warn,
                     base: Path | None) -> Shape | None:
    xyz, rpy = _origin(collision)
    geometry = collision.find('geometry')
    if geometry is None or not geometry.children:
        warn(f'{collision.where}: <collision> of link {link!r} has no geometry; left out')
        return None
    shape = geometry.children[0]
    if shape.tag == 'box':
        return Shape('box', tuple(_attribute_vector(shape, 'size', 3)), xyz, rpy)
    if shape.tag == 'cylinder':
        radius, length = (float(shape.attrib.get(k, '0')) for k in ('radius', 'length'))
        return Shape('cylinder', (radius, length), xyz, rpy)
    if shape.tag == 'sphere':
        return Shape('sphere', (float(shape.attrib.get('radius', '0')),), xyz, rpy)
    if shape.tag == 'mesh':
        name = _mesh(spec, geometry, link, warn, base)
        return Shape('mesh', (), xyz, rpy, mesh=name) if name else None
    warn(f'{shape.where}: <{shape.tag}> geometry is not a URDF shape; this collision is left out')
    return None


def _dynamics(joint: mujoco.MjsJoint, node: Node | None, warn: Warn) -> None:
    """A URDF joint's <dynamics> damping and friction (as sdformat carries them into
    Gazebo); a <mimic> is one line: Gazebo needs a plugin for it, the kit has none."""
    dynamics = node.find('dynamics') if node is not None else None
    if dynamics is not None:
        damping = float(dynamics.attrib.get('damping', '0') or 0)
        current = joint.damping  # MuJoCo 4: (linear, ...) coefficients; 3.x: one number
        joint.damping = [damping, *list(current)[1:]] if hasattr(current, '__len__') else damping
        joint.frictionloss = float(dynamics.attrib.get('friction', '0') or 0)
    mimic = node.find('mimic') if node is not None else None
    if mimic is not None:
        warn(f"{mimic.where}: <mimic> is not simulated by robot_lab's simulator; the joint "
             f'moves on its own')


def _inertial(body: mujoco.MjsBody, link: Node, moves: bool, warn: Warn) -> None:
    inertial = link.find('inertial')
    if inertial is None:
        if moves:
            warn(f'{link.where}: link {link.attrib["name"]!r} has no <inertial>; the simulator '
                 f'gives it {DEFAULT_MASS} kg and {DEFAULT_INERTIA} kg m² (Gazebo would drop it)')
            body.mass = DEFAULT_MASS
            body.inertia = [DEFAULT_INERTIA] * 3
            body.explicitinertial = True
        return
    xyz, rpy = _origin(inertial)
    mass_node = inertial.find('mass')
    mass = float(mass_node.attrib.get('value', '0')) if mass_node is not None else 0.0
    inertia = inertial.find('inertia')
    values = [float(inertia.attrib.get(k, '0')) if inertia is not None else 0.0
              for k in ('ixx', 'iyy', 'izz', 'ixy', 'ixz', 'iyz')]
    if moves and (mass <= 0.0 or min(values[:3]) <= 0.0):
        warn(f'{inertial.where}: link {link.attrib["name"]!r} has mass {mass} and inertia '
             f'{values[:3]}; the simulator uses at least {DEFAULT_MASS} kg and '
             f'{DEFAULT_INERTIA} kg m² on each axis')
        mass = max(mass, DEFAULT_MASS)
        values = [max(v, DEFAULT_INERTIA) for v in values[:3]] + values[3:]
    body.mass = mass
    body.ipos = list(xyz)
    body.iquat = quat_from_rpy(*rpy)
    body.fullinertia = values
    body.explicitinertial = True


def add_robot(spec: mujoco.MjSpec, urdf_text: str, name: str, source: str,
              xyz: tuple[float, float, float], rpy: tuple[float, float, float],
              warn: Warn, root: Node | None = None) -> SpawnedRobot:
    """The URDF's links as bodies of `spec` under a body named `name`, posed at xyz/rpy;
    `root`, the text's element tree if given (an SDF robot's, with the SDF's lines)."""
    tree = parse_urdf(urdf_text, source)  # urdfdom's refusals, file:line
    root = root if root is not None else parse(urdf_text, source)
    if any(str(b.name).startswith(f'{name}::') or b.name == name for b in spec.bodies):
        raise SimulationError(f'an entity named {name!r} already exists in the world',
                              fix='give the robot another -name')
    tags = read_gazebo_tags(root, warn)
    folder = Path(source).parent if Path(source).is_file() else None  # relative mesh paths
    for element in root.children:
        if element.tag not in ('link', 'joint', 'gazebo', 'material'):
            warn(f"{element.where}: <{element.tag}> is not simulated by robot_lab's simulator "
                 f'(DiffDrive and the other <gazebo> systems drive joints); ignored')
    links = {n.attrib.get('name', ''): n for n in root.findall('link')}
    joint_nodes = {n.attrib.get('name', ''): n for n in root.findall('joint')}
    driven = {j for d in tags.diff_drives for j in d.left_joints + d.right_joints}
    bodies: dict[str, str] = {}
    joints: dict[str, str] = {}

    def build(link: str, body: mujoco.MjsBody, moves: bool) -> None:
        body.name = f'{name}::{link}'
        bodies[link] = body.name
        node = links[link]
        _inertial(body, node, moves, warn)
        if moves and link in tags.no_gravity:
            body.gravcomp = 1.0  # <gravity>false: gravity cancelled on this link
        friction = tags.friction.get(link)
        for index, collision in enumerate(node.findall('collision')):
            shape = _collision_shape(spec, collision, link, warn, folder)
            if shape is not None:
                add_shape(body, shape, f'{body.name}::collision{index}', friction)
        for joint in tree.child_joints.get(link, []):
            child = body.add_body()
            child.pos = list(joint.xyz)
            child.quat = quat_from_rpy(*joint.rpy)
            child_moves = moves or joint.type != 'fixed'
            if joint.type in ('revolute', 'continuous', 'prismatic'):
                mj_joint = child.add_joint()
                mj_joint.name = f'{name}::{joint.name}'
                mj_joint.type = (mujoco.mjtJoint.mjJNT_SLIDE if joint.type == 'prismatic'
                                 else mujoco.mjtJoint.mjJNT_HINGE)
                mj_joint.axis = list(joint.axis)
                if joint.type != 'continuous' and joint.limit is not None:
                    mj_joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
                    mj_joint.range = [joint.limit.lower, joint.limit.upper]
                if joint.name not in driven:  # Gazebo sets a driven wheel's velocity
                    _dynamics(mj_joint, joint_nodes.get(joint.name), warn)
                joints[joint.name] = mj_joint.name
            elif joint.type != 'fixed':
                warn(f'{source}:{joint.line}: joint {joint.name!r} of type {joint.type!r} is '
                     f"not supported by robot_lab's simulator; simulated as fixed")
            build(joint.child, child, child_moves)

    base = spec.worldbody.add_body()
    base.pos = list(xyz)
    base.quat = quat_from_rpy(*rpy)
    if tree.root == 'world':
        build(tree.root, base, False)
    else:
        base.add_freejoint().name = f'{name}::free'
        build(tree.root, base, True)
    if not any(n.findall('collision') for n in links.values()):
        warn(f'{source}:{root.line}: robot {tree.name!r} has no <collision> in any link: '
             f'nothing holds it up, it falls through the ground (as in Gazebo)')
    return SpawnedRobot(name, tree, tags, bodies, joints)
