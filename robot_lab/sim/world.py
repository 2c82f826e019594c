"""SDF worlds (1.6-1.11) as Gazebo Harmonic loads them, built into a MuJoCo model spec.

What a lab's world holds is read: `<physics>` (max_step_size, real_time_factor), static and
dynamic `<model>`s of `<link>`s with box, cylinder, sphere, plane and mesh collisions, poses, and
`<include>` of models found on GZ_SIM_RESOURCE_PATH or among the kit's own (ground_plane,
sun, walls). What only a renderer or GUI uses (lights, visuals, materials, the GUI's
plugins) has no effect on the simulation and passes quietly; any other element is one
warning line naming it, its file and its line, so nothing is dropped unseen.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

from robot_lab.sim.meshes import add_mesh, resolve_mesh
from robot_lab.sim.sdf_robot import is_robot, sdf_robot
from robot_lab.sim.shapes import Shape, add_shape, quat_from_rpy
from robot_lab.sim.xml_tree import Node, SimulationError, Warn, parse, vector

__all__ = ['KIT_RESOURCES', 'SdfRobot', 'WorldInfo', 'add_model', 'find_world', 'load_world',
           'resource_path']

KIT_RESOURCES = Path(__file__).resolve().parents[1] / 'data' / 'ament_packages' / 'ros_gz_sim'
# Elements a renderer or GUI reads: no physics effect, so no warning.
RENDERING = {'light', 'visual', 'gui', 'scene', 'material', 'atmosphere', 'audio', 'wind',
             'magnetic_field', 'spherical_coordinates', 'self_collide', 'enable_wind',
             'allow_auto_disable', 'sensor', 'surface'}
# World systems every world has in the kit (Gazebo loads them from the world's plugins).
WORLD_SYSTEMS = ('physics', 'user-commands', 'usercommands', 'scene-broadcaster',
                 'scenebroadcaster', 'sensors', 'contact', 'imu', 'imu-system',
                 'forcetorque', 'navsat', 'altimeter', 'magnetometer', 'air-pressure')


@dataclass
class SdfRobot:
    """A world's SDF model with joints, plugins or sensors, to spawn as a robot."""

    urdf: str
    root: Node
    name: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    source: str


@dataclass
class WorldInfo:
    """What the simulation loop needs from the world file besides the bodies."""

    name: str = 'default'
    step: float = 0.001
    real_time_factor: float = 1.0
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.8)
    models: list[str] = field(default_factory=list)
    robots: list[SdfRobot] = field(default_factory=list)  # spawned once the world is built


def resource_path() -> list[Path]:
    """Where `model://` and world names are found: GZ_SIM_RESOURCE_PATH, then the kit's."""
    folders = [Path(p) for p in os.environ.get('GZ_SIM_RESOURCE_PATH', '').split(':') if p]
    return [*folders, KIT_RESOURCES / 'worlds', KIT_RESOURCES / 'models']


def find_world(name: str) -> Path:
    """A world file as `gz sim` finds it: a path, else a name on the resource path."""
    path = Path(name).expanduser()
    if path.is_file():
        return path
    for folder in resource_path():
        if (folder / name).is_file():
            return folder / name
    kit = sorted(p.name for p in (KIT_RESOURCES / 'worlds').glob('*.sdf'))
    raise SimulationError(f'unable to find or download file {name!r}',
                          fix=f"give a path to an .sdf file, or one of the kit's worlds: "
                              f'{", ".join(kit)}')


def _pose(node: Node) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    values = vector(node.find('pose'), 6)
    return (values[0], values[1], values[2]), (values[3], values[4], values[5])


def _geometry(collision: Node, warn: Warn, spec: mujoco.MjSpec, owner: str) -> Shape | None:
    geometry = collision.find('geometry')
    xyz, rpy = _pose(collision)
    shapes = geometry.children if geometry is not None else []
    for shape in shapes:
        if shape.tag == 'box':
            return Shape('box', tuple(vector(shape.find('size'), 3, 1.0)), xyz, rpy)
        if shape.tag == 'cylinder':
            return Shape('cylinder', (shape.number('radius', 0.5), shape.number('length', 1.0)),
                         xyz, rpy)
        if shape.tag == 'sphere':
            return Shape('sphere', (shape.number('radius', 0.5),), xyz, rpy)
        if shape.tag == 'plane':
            normal = vector(shape.find('normal'), 3)
            if normal[:2] != [0.0, 0.0]:
                warn(f'{shape.where}: <plane> with normal {normal}: only an upward normal is '
                     f'supported; collides as 0 0 1')
            return Shape('plane', (), xyz, rpy)
        if shape.tag == 'mesh':
            path = resolve_mesh(shape.value('uri'), shape, warn, models=resource_path(),
                                base=Path(shape.source).parent)
            name = add_mesh(spec, path, vector(shape.find('scale'), 3, 1.0), owner, shape,
                            warn) if path is not None else ''
            return Shape('mesh', (), xyz, rpy, mesh=name) if name else None
        warn(f"{shape.where}: <{shape.tag}> geometry is not supported by robot_lab's "
             f'simulator; this collision is left out')
    return None


def _inertial(body: mujoco.MjsBody, inertial: Node | None) -> None:
    """SDF's <inertial>: mass (default 1), its pose (the centre of mass) and the full
    inertia matrix (default: the unit diagonal)."""
    mass = inertial.number('mass', 1.0) if inertial is not None else 1.0
    inertia = inertial.find('inertia') if inertial is not None else None
    body.mass = mass
    body.fullinertia = [inertia.number(k, 1.0 if k in ('ixx', 'iyy', 'izz') else 0.0)
                        if inertia is not None else (1.0 if k in ('ixx', 'iyy', 'izz') else 0.0)
                        for k in ('ixx', 'iyy', 'izz', 'ixy', 'ixz', 'iyz')]
    if inertial is not None:
        xyz, rpy = _pose(inertial)
        body.ipos = list(xyz)
        body.iquat = quat_from_rpy(*rpy)
    body.explicitinertial = True


def _friction(collision: Node) -> float | None:
    """A collision's <surface><friction> mu (ODE's, else Bullet's), or None."""
    surface = collision.find('surface')
    friction = surface.find('friction') if surface is not None else None
    if friction is None:
        return None
    for engine in ('ode', 'bullet'):
        block = friction.find(engine)
        if block is not None and block.find('mu' if engine == 'ode' else 'friction') is not None:
            return block.number('mu' if engine == 'ode' else 'friction', 1.0)
    return None


class _Builder:
    def __init__(self, spec: mujoco.MjSpec, info: WorldInfo, warn: Warn) -> None:
        self.spec, self.info, self.warn = spec, info, warn

    def unsupported(self, node: Node, where: str) -> None:
        self.warn(f"{node.where}: <{node.tag}> in <{where}> is not supported by robot_lab's "
                  f'simulator; ignored')

    def world(self, world: Node) -> None:
        self.info.name = world.attrib.get('name', 'default')
        for child in world.children:
            if child.tag == 'physics':
                self.physics(child)
            elif child.tag == 'gravity':
                g = vector(child, 3)
                self.info.gravity = (g[0], g[1], g[2])
            elif child.tag == 'model':
                self.top_model(child)
            elif child.tag == 'include':
                self.include(child)
            elif child.tag == 'plugin':
                self.world_plugin(child)
            elif child.tag not in RENDERING:
                self.unsupported(child, 'world')

    def physics(self, node: Node) -> None:
        """max_step_size and real_time_factor, all gz-sim reads here (its `type` attribute
        and real_time_update_rate it ignores too; the engine is the Physics system's)."""
        self.info.step = node.number('max_step_size', 0.001)
        self.info.real_time_factor = node.number('real_time_factor', 1.0)
        for child in node.children:
            if child.tag in ('dart', 'ode', 'bullet', 'simbody') and child.children:
                self.warn(f"{child.where}: <{child.tag}> solver settings: robot_lab's "
                          f'simulator runs MuJoCo with its own; ignored')
            elif child.tag not in ('max_step_size', 'real_time_factor',
                                   'real_time_update_rate', 'dart', 'ode', 'bullet', 'simbody'):
                self.unsupported(child, 'physics')

    def world_plugin(self, node: Node) -> None:
        filename = node.attrib.get('filename', '').lower()
        name = filename.removeprefix('lib').removesuffix('.so')
        for prefix in ('gz-sim-', 'ignition-gazebo-'):
            name = name.removeprefix(prefix)
        if name.removesuffix('-system') not in WORLD_SYSTEMS and name not in WORLD_SYSTEMS:
            self.warn(f'{node.where}: world plugin {node.attrib.get("name", filename)!r} is '
                      f"not supported by robot_lab's simulator; ignored")

    def include(self, node: Node) -> None:
        for child in node.children:
            if child.tag not in ('uri', 'name', 'pose', 'static'):
                self.unsupported(child, 'include')
        uri = node.value('uri')
        model_name = uri.removeprefix('model://').rstrip('/').split('/')[-1]
        for folder in resource_path():
            candidate = folder / model_name / 'model.sdf'
            if candidate.is_file():
                root = parse(candidate.read_bytes(), str(candidate))
                model = root.find('model')
                if model is None:
                    break
                if node.find('name') is not None:
                    model.attrib['name'] = node.value('name')
                if node.find('pose') is not None:
                    model.children = [c for c in model.children if c.tag != 'pose']
                    model.children.append(node.find('pose'))  # type: ignore[arg-type]
                if node.find('static') is not None:
                    model.children.append(node.find('static'))  # type: ignore[arg-type]
                self.top_model(model)
                return
            if (folder / model_name / 'model.config').is_file() and model_name == 'sun':
                return
        if model_name == 'sun':  # a light: nothing to simulate
            return
        if uri.startswith(('http://', 'https://')):  # Gazebo would download it from Fuel
            self.warn(f"{node.where}: <include> of {uri!r}: robot_lab's simulator does not "
                      f'download models (no network); left out. Put the model on '
                      f'GZ_SIM_RESOURCE_PATH and include it as model://<name>')
            return
        raise SimulationError(f'<include> of {uri!r}: no such model on the resource path',
                              file=node.source, line=node.line,
                              fix='put the model folder on GZ_SIM_RESOURCE_PATH, or use one of '
                                  "the kit's: " + ', '.join(
                                      sorted(p.name for p in (KIT_RESOURCES / 'models').iterdir())))

    def top_model(self, model: Node) -> None:
        """A model of the world: a robot (joints, plugins, sensors) is queued to spawn as
        one; any other is built here."""
        if is_robot(model):
            urdf, root, xyz, rpy = sdf_robot(model, self.warn, *_pose(model))
            self.info.robots.append(SdfRobot(urdf, root, model.attrib.get('name', 'robot'),
                                             xyz, rpy, model.source))
        else:
            self.model(model, None)

    def model(self, model: Node, parent: mujoco.MjsFrame | None) -> mujoco.MjsFrame:
        """A model is a frame, not a body: its links stay top-level bodies, so a dynamic
        link's free joint compiles (MuJoCo allows one only on a child of the world)."""
        name = model.attrib.get('name', f'model_{len(self.info.models)}')
        self.info.models.append(name)
        static = model.value('static', 'false').lower() in ('1', 'true')
        xyz, rpy = _pose(model)
        frame = (parent or self.spec.worldbody).add_frame()
        frame.name = name
        frame.pos = list(xyz)
        frame.quat = quat_from_rpy(*rpy)
        for child in model.children:
            if child.tag == 'link':
                self.link(child, frame, static, name)
            elif child.tag == 'model':
                self.model(child, frame)
            elif child.tag == 'include':
                self.include(child)
            elif child.tag not in RENDERING | {'pose', 'static', 'plugin'}:
                self.unsupported(child, 'model')
            elif child.tag == 'plugin':
                self.warn(f'{child.where}: model plugin {child.attrib.get("name", "")!r} in an '
                          f'SDF world is not supported yet; spawn the robot from URDF instead')
        return frame

    def link(self, link: Node, frame: mujoco.MjsFrame, static: bool, model: str) -> None:
        xyz, rpy = _pose(link)
        body = frame.add_body()
        body.name = f'{model}::{link.attrib.get("name", "link")}'
        body.pos = list(xyz)
        body.quat = quat_from_rpy(*rpy)
        if not static:
            body.add_freejoint()
            _inertial(body, link.find('inertial'))
            if link.value('gravity', 'true').lower() in ('0', 'false'):
                body.gravcomp = 1.0  # gravity cancelled on this body, as <gravity>false
        kinematic = link.find('kinematic')
        if kinematic is not None and kinematic.text.strip().lower() in ('1', 'true'):
            self.warn(f"{kinematic.where}: <kinematic> links are not supported by robot_lab's "
                      f'simulator; simulated as dynamic')
        for index, child in enumerate(link.children):
            if child.tag == 'collision':
                self.collision_children(child)
                shape = _geometry(child, self.warn, self.spec, f'model {model!r}')
                if shape is not None:
                    add_shape(body, shape, f'{body.name}::{child.attrib.get("name", index)}',
                              _friction(child))
            elif child.tag not in RENDERING | {'pose', 'inertial', 'kinematic', 'gravity'}:
                self.unsupported(child, 'link')

    def collision_children(self, collision: Node) -> None:
        """Say what a collision holds that the kit does not simulate: anything but its
        geometry, pose and surface friction."""
        for child in collision.children:
            if child.tag == 'surface':
                extra = [c.tag for c in child.children if c.tag != 'friction']
                if extra:
                    self.warn(f"{child.where}: <surface> {', '.join(f'<{t}>' for t in extra)} "
                              f"not supported by robot_lab's simulator (friction is); ignored")
            elif child.tag not in ('geometry', 'pose', 'laser_retro', 'max_contacts'):
                self.unsupported(child, 'collision')


def add_model(spec: mujoco.MjSpec, info: WorldInfo, text: str, source: str, name: str,
              xyz: tuple[float, float, float], rpy: tuple[float, float, float],
              warn: Warn) -> str:
    """`create -file model.sdf` (or `-string '<sdf><model>...'`): an SDF model joins the
    world at create's pose, which replaces the model's own (as gz-sim's create does); its
    name is `name` if given. Returns the name it got."""
    root = parse(text, source)
    model = root if root.tag == 'model' else root.find('model')
    if model is None or root.tag not in ('sdf', 'model'):
        raise SimulationError(f'no <sdf><model> in it (the root is <{root.tag}>)', file=source,
                              line=root.line, fix='create takes a URDF <robot> or an SDF '
                                                  '<model>; a world goes to gz sim')
    if name:
        model.attrib['name'] = name
    name = model.attrib.get('name', '')
    if not name or any(b.name == name or str(b.name).startswith(f'{name}::')
                       for b in spec.bodies):
        raise SimulationError(f'an entity named {name!r} already exists in the world'
                              if name else 'the model has no name', file=source,
                              line=model.line, fix='give the model another -name')
    if is_robot(model):  # joints, plugins, sensors: Simulation.spawn_model spawns it
        urdf, tree, at_xyz, at_rpy = sdf_robot(model, warn, xyz, rpy)
        info.robots.append(SdfRobot(urdf, tree, name, at_xyz, at_rpy, source))
        return name
    frame = _Builder(spec, info, warn).model(model, None)
    frame.pos = list(xyz)
    frame.quat = quat_from_rpy(*rpy)
    return name


def load_world(path: Path, warn: Warn) -> tuple[mujoco.MjSpec, WorldInfo]:
    """The world file's bodies in a new spec, and its name, step and real-time factor."""
    root = parse(path.read_bytes(), str(path))
    world = root.find('world') if root.tag == 'sdf' else None
    if world is None:
        raise SimulationError('no <sdf><world> in the file', file=str(path), line=root.line,
                              fix='a world file is <sdf version="1.9"><world name="..."> ...')
    spec = mujoco.MjSpec()
    info = WorldInfo()
    _Builder(spec, info, warn).world(world)
    spec.modelname = info.name
    spec.compiler.degree = False  # URDF joint limits are radians (MuJoCo's default: degrees)
    spec.option.timestep = info.step
    spec.option.gravity = list(info.gravity)
    # the wheels' velocity servos are stiff for a light wheel: implicit in velocity
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    return spec, info
