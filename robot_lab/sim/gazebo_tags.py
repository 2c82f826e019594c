"""A URDF's `<gazebo>` tags as Gazebo Harmonic reads them: systems, sensors, surfaces.

sdformat turns `<gazebo>` (model-wide) and `<gazebo reference="link">` blocks into SDF:
`<plugin>`s become model systems, `<sensor>`s attach to the link, `<mu1>`/`<mu2>` set the
link's collision friction. The kit reads the same blocks into plain settings the simulator's
systems take, with Gazebo's defaults; anything it does not simulate is one warning line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from robot_lab.sim.xml_tree import Node, Warn

__all__ = ['DiffDriveSettings', 'GazeboTags', 'ImuSettings', 'JointPositionSettings',
           'JointStateSettings', 'LidarSettings', 'read_gazebo_tags']


@dataclass
class DiffDriveSettings:
    """gz::sim::systems::DiffDrive's parameters (empty topics: Gazebo's defaults)."""

    left_joints: list[str]
    right_joints: list[str]
    wheel_separation: float = 1.0
    wheel_radius: float = 0.2
    topic: str = ''
    odom_topic: str = ''
    tf_topic: str = ''
    frame_id: str = ''
    child_frame_id: str = ''
    odom_publish_frequency: float = 50.0
    max_linear_velocity: float = math.inf
    min_linear_velocity: float = -math.inf
    max_angular_velocity: float = math.inf
    min_angular_velocity: float = -math.inf
    max_linear_acceleration: float = math.inf
    min_linear_acceleration: float = -math.inf
    max_angular_acceleration: float = math.inf
    min_angular_acceleration: float = -math.inf


@dataclass
class JointPositionSettings:
    """gz::sim::systems::JointPositionController: a PID on the joint's force, its target from
    gz.msgs.Double on `topic` (empty: /model/<model>/joint/<joint>/0/cmd_pos)."""

    joint: str
    topic: str = ''
    p_gain: float = 1.0
    i_gain: float = 0.0
    d_gain: float = 0.0
    i_max: float = 1.0
    i_min: float = -1.0
    cmd_max: float = 1000.0
    cmd_min: float = -1000.0
    cmd_offset: float = 0.0
    initial_position: float = 0.0


@dataclass
class JointStateSettings:
    """gz::sim::systems::JointStatePublisher: which joints (none named: all) and topic."""

    joints: list[str] = field(default_factory=list)
    topic: str = ''


@dataclass
class LidarSettings:
    """A `lidar`/`gpu_lidar` sensor on a link: its beams, ranges, rate, topic and frame."""

    name: str
    link: str
    samples: int = 640
    min_angle: float = 0.0
    max_angle: float = 0.0
    range_min: float = 0.0
    range_max: float = 10.0
    update_rate: float = 10.0
    topic: str = ''
    frame_id: str = ''
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    noise_stddev: float = 0.0
    noise_mean: float = 0.0


@dataclass
class ImuSettings:
    """An `imu` sensor on a link: rate (0: every step, SDF's default), topic, frame, noise."""

    name: str
    link: str
    update_rate: float = 0.0
    topic: str = ''
    frame_id: str = ''
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    # (mean, stddev) of gaussian noise per axis, for angular_velocity and linear_acceleration
    noise: dict[str, tuple[float, float]] = field(default_factory=dict)


@dataclass
class GazeboTags:
    """Everything the `<gazebo>` blocks asked for."""

    diff_drives: list[DiffDriveSettings] = field(default_factory=list)
    joint_states: list[JointStateSettings] = field(default_factory=list)
    lidars: list[LidarSettings] = field(default_factory=list)
    imus: list[ImuSettings] = field(default_factory=list)
    joint_positions: list[JointPositionSettings] = field(default_factory=list)
    friction: dict[str, float] = field(default_factory=dict)  # link -> min(mu1, mu2)
    no_gravity: set[str] = field(default_factory=set)  # <gravity>false / <turnGravityOff>


_DIFF_DRIVE_NUMBERS = ('wheel_separation', 'wheel_radius', 'odom_publish_frequency',
                       'max_linear_velocity', 'min_linear_velocity', 'max_angular_velocity',
                       'min_angular_velocity', 'max_linear_acceleration',
                       'min_linear_acceleration', 'max_angular_acceleration',
                       'min_angular_acceleration')
_DIFF_DRIVE_TEXTS = ('topic', 'odom_topic', 'tf_topic', 'frame_id', 'child_frame_id')
# Link-level tags sdformat reads that only a renderer uses (no warning)
_QUIET = {'material', 'selfCollide', 'self_collide', 'visual', 'provideFeedback'}
# ODE's contact and joint tuning: no MuJoCo equivalent; one line per <gazebo> block
_ODE_TUNING = {'kp', 'kd', 'maxVel', 'minDepth', 'fdir1', 'maxContacts',
               'implicitSpringDamper', 'stopCfm', 'stopErp', 'springStiffness',
               'springReference'}


def _system_name(plugin: Node) -> str:
    name = plugin.attrib.get('name', '')
    return name.split('::')[-1] if name else plugin.attrib.get('filename', '')


def _diff_drive(plugin: Node, warn: Warn) -> DiffDriveSettings:
    settings = DiffDriveSettings([c.text for c in plugin.findall('left_joint')],
                                 [c.text for c in plugin.findall('right_joint')])
    for tag in _DIFF_DRIVE_NUMBERS:
        setattr(settings, tag, plugin.number(tag, getattr(settings, tag)))
    for tag in _DIFF_DRIVE_TEXTS:
        setattr(settings, tag, plugin.value(tag))
    # Gazebo's limiter takes a bare max/min for both directions as well
    for kind in ('velocity', 'acceleration'):
        for motion in ('linear', 'angular'):
            maximum = getattr(settings, f'max_{motion}_{kind}')
            if plugin.find(f'min_{motion}_{kind}') is None and math.isfinite(maximum):
                setattr(settings, f'min_{motion}_{kind}', -maximum)
    known = set(_DIFF_DRIVE_NUMBERS) | set(_DIFF_DRIVE_TEXTS) | {'left_joint', 'right_joint'}
    for child in plugin.children:
        if child.tag not in known:
            warn(f'{child.where}: DiffDrive parameter <{child.tag}> is not supported by '
                 f"robot_lab's simulator; ignored")
    return settings


_PID_NUMBERS = ('p_gain', 'i_gain', 'd_gain', 'i_max', 'i_min', 'cmd_max', 'cmd_min',
                'cmd_offset', 'initial_position')


def _joint_position(plugin: Node, warn: Warn) -> list[JointPositionSettings]:
    topic = plugin.value('topic') or plugin.value('sub_topic')
    controllers = []
    for name in plugin.findall('joint_name'):
        settings = JointPositionSettings(name.text, topic)
        for tag in _PID_NUMBERS:
            setattr(settings, tag, plugin.number(tag, getattr(settings, tag)))
        controllers.append(settings)
    for child in plugin.children:
        if child.tag not in {*_PID_NUMBERS, 'joint_name', 'topic', 'sub_topic'}:
            warn(f'{child.where}: JointPositionController parameter <{child.tag}> is not '
                 f"supported by robot_lab's simulator; ignored")
    return controllers


def _lidar(sensor: Node, link: str, warn: Warn) -> LidarSettings:
    settings = LidarSettings(sensor.attrib.get('name', 'lidar'), link)
    ray = sensor.find('lidar') or sensor.find('ray')
    if ray is not None:
        scan = ray.find('scan')
        horizontal = scan.find('horizontal') if scan is not None else None
        if horizontal is not None:
            settings.samples = int(horizontal.number('samples', 640))
            settings.min_angle = horizontal.number('min_angle', 0.0)
            settings.max_angle = horizontal.number('max_angle', 0.0)
            if horizontal.number('resolution', 1.0) != 1.0:
                warn(f'{horizontal.where}: <resolution> other than 1 is not supported; '
                     f'one ray per sample')
        vertical = scan.find('vertical') if scan is not None else None
        if vertical is not None and vertical.number('samples', 1) > 1:
            warn(f'{vertical.where}: <vertical> samples > 1 (a 3D lidar) are not supported; '
                 f'the horizontal plane only')
        ranges = ray.find('range')
        if ranges is not None:
            settings.range_min = ranges.number('min', 0.0)
            settings.range_max = ranges.number('max', 10.0)
        noise = ray.find('noise')
        if noise is not None:
            settings.noise_mean = noise.number('mean', 0.0)
            settings.noise_stddev = noise.number('stddev', 0.0)
    _place(sensor, settings, default_rate=10.0)
    for child in sensor.children:
        if child.tag not in ('lidar', 'ray', 'update_rate', 'topic', 'gz_frame_id', 'frame_id',
                             'ignition_frame_id', 'pose', 'always_on', 'alwaysOn',
                             'visualize', 'enable_metrics'):
            warn(f'{child.where}: <{child.tag}> in sensor {settings.name!r} is not supported '
                 f"by robot_lab's simulator; ignored")
    return settings


def _place(sensor: Node, settings: LidarSettings | ImuSettings, default_rate: float) -> None:
    """What every sensor tag says alike: its rate, topic, frame id (gz_frame_id, frame_id or
    Fortress's ignition_frame_id) and pose on its link (missing numbers: 0)."""
    settings.update_rate = sensor.number('update_rate', default_rate)
    settings.topic = sensor.value('topic')
    settings.frame_id = (sensor.value('gz_frame_id') or sensor.value('frame_id')
                         or sensor.value('ignition_frame_id'))
    pose = sensor.find('pose')
    if pose is not None and pose.text:
        values = [float(v) for v in pose.text.split()] + [0.0] * 6
        settings.xyz = (values[0], values[1], values[2])
        settings.rpy = (values[3], values[4], values[5])


def _imu(sensor: Node, link: str, warn: Warn) -> ImuSettings:
    settings = ImuSettings(sensor.attrib.get('name', 'imu'), link)
    _place(sensor, settings, default_rate=0.0)
    imu = sensor.find('imu')
    for quantity in (imu.children if imu is not None else []):
        if quantity.tag not in ('angular_velocity', 'linear_acceleration'):
            warn(f'{quantity.where}: <{quantity.tag}> in imu {settings.name!r} is not '
                 f"supported by robot_lab's simulator; ignored")
            continue
        for axis in quantity.children:
            noise = axis.find('noise')
            if noise is not None:
                settings.noise[f'{quantity.tag}.{axis.tag}'] = (noise.number('mean', 0.0),
                                                                noise.number('stddev', 0.0))
    for child in sensor.children:
        if child.tag not in ('imu', 'update_rate', 'topic', 'gz_frame_id', 'frame_id',
                             'ignition_frame_id', 'pose', 'always_on', 'alwaysOn',
                             'visualize', 'enable_metrics'):
            warn(f'{child.where}: <{child.tag}> in sensor {settings.name!r} is not supported '
                 f"by robot_lab's simulator; ignored")
    return settings


def read_gazebo_tags(robot: Node, warn: Warn) -> GazeboTags:
    """The `<gazebo>` blocks of a URDF root element, read as sdformat and gz-sim do."""
    tags = GazeboTags()
    for block in robot.findall('gazebo'):
        link = block.attrib.get('reference', '')
        mu = [block.number(tag, math.nan) for tag in ('mu1', 'mu2')]
        if not all(math.isnan(m) for m in mu) and link:
            tags.friction[link] = min(m for m in mu if not math.isnan(m))
        for child in block.children:
            if child.tag == 'plugin':
                system = _system_name(child)
                if system in ('DiffDrive', 'gz-sim-diff-drive-system'):
                    tags.diff_drives.append(_diff_drive(child, warn))
                elif system in ('JointPositionController',
                                'gz-sim-joint-position-controller-system'):
                    tags.joint_positions += _joint_position(child, warn)
                elif system in ('JointStatePublisher', 'gz-sim-joint-state-publisher-system'):
                    tags.joint_states.append(JointStateSettings(
                        [c.text for c in child.findall('joint_name')], child.value('topic')))
                    for extra in child.children:
                        if extra.tag not in ('joint_name', 'topic'):
                            warn(f'{extra.where}: JointStatePublisher parameter '
                                 f"<{extra.tag}> is not supported by robot_lab's simulator; "
                                 f'ignored')
                else:
                    warn(f'{child.where}: plugin {child.attrib.get("name", system)!r} is not '
                         f"supported by robot_lab's simulator; ignored")
            elif child.tag == 'sensor':
                kind = child.attrib.get('type', '')
                if kind in ('gpu_lidar', 'lidar', 'gpu_ray', 'ray'):
                    tags.lidars.append(_lidar(child, link, warn))
                elif kind == 'imu':
                    tags.imus.append(_imu(child, link, warn))
                else:
                    warn(f'{child.where}: sensor type {kind!r} is not supported by '
                         f"robot_lab's simulator yet; ignored")
            elif child.tag in ('gravity', 'turnGravityOff') and link:
                off = child.text.strip().lower() in ('1', 'true')
                if off == (child.tag == 'turnGravityOff'):
                    tags.no_gravity.add(link)
            elif child.tag not in ('mu1', 'mu2') and child.tag not in _QUIET | _ODE_TUNING:
                warn(f'{child.where}: <gazebo> element <{child.tag}> is not supported by '
                     f"robot_lab's simulator; ignored")
        tuning = [c for c in block.children if c.tag in _ODE_TUNING]
        if tuning:
            warn(f"{tuning[0].where}: {', '.join(f'<{c.tag}>' for c in tuning)}: ODE's "
                 f"contact tuning, which robot_lab's simulator (MuJoCo) has no equivalent "
                 f'of; ignored')
    return tags
