"""The 3D view's displays, as RViz names them: what each takes from ROS and sends on.

Each display turns its messages into plain data (numbers, lists, binary buffers) for its
twin in the browser bundle (js/scene_view/src/displays.js), under the same `kind`. A
display that follows a topic keeps only what the picture needs (the latest scan, the
markers alive, the last poses) and says when it has something new; the view sends that at
the display rate. A new display is one class here, one in displays.js, and its entry in
`BY_TYPE` if it draws a message type.
"""

from __future__ import annotations

import math
import threading
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

from robot_lab.scene.frames import FrameTree, Pose
from robot_lab.scene.meshes import MeshFiles, mesh_uris

if TYPE_CHECKING:
    from collections.abc import Iterable

__all__ = [
    'BY_TYPE',
    'TF',
    'Display',
    'Grid',
    'LaserScan',
    'Markers',
    'Odometry',
    'Outbox',
    'Path',
    'PoseStamped',
    'RobotModel',
]

# visualization_msgs/Marker actions and the type that names a mesh
_ADD, _DELETE, _DELETEALL, _MESH = 0, 2, 3, 10


@dataclass
class Outbox:
    """One message to the browser being built: its binary buffers and meshes."""

    buffers: list[bytes] = field(default_factory=list)
    meshes: dict[str, object] = field(default_factory=dict)

    def buffer(self, data: bytes) -> int:
        self.buffers.append(data)
        return len(self.buffers) - 1


def _pose(p: Any) -> Pose:
    """geometry_msgs/Pose → (x, y, z, qx, qy, qz, qw)."""
    o, q = p.position, p.orientation
    return (o.x, o.y, o.z, q.x, q.y, q.z, q.w)


class Display:
    """One display: `spec()` builds its browser side, `data()` feeds it."""

    kind: ClassVar[str] = ''
    label: ClassVar[str] = ''  # RViz's name for it, in status lines
    type_names: ClassVar[tuple[str, ...]] = ()  # the ROS message types it draws
    latched: ClassVar[bool] = False  # take a transient-local publisher's last message

    def __init__(self, topic: str | None = None, name: str | None = None,
                 **options: object) -> None:
        self.topic = topic
        self.id = name or (f'{self.kind}:{topic}' if topic else self.kind)
        self.options = options
        self.count = 0
        self.type_name = self.type_names[0] if self.type_names else ''
        self._lock = threading.Lock()
        self._dirty = False

    def spec(self) -> dict[str, object]:
        return {'id': self.id, 'kind': self.kind, **self.options}

    def take(self, msg: Any) -> None:
        """A message from the display's topic (on the executor thread)."""
        with self._lock:
            self._take(msg)
            self.count += 1
            self._dirty = True

    def _take(self, msg: Any) -> None:
        raise NotImplementedError

    def data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        """What the browser should get now: everything (`full`), else what is new, or None."""
        with self._lock:
            if not (full or self._dirty):
                return None
            self._dirty = False
            return self._data(out, full)

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        return None

    def frame(self) -> str | None:
        """The frame its data is drawn in (None: no data yet, or drawn in the fixed frame)."""
        return None

    def status(self, poses: dict[str, Pose | None], tree: FrameTree, fixed: str) -> list[str]:
        """RViz's status lines for it, when something is wrong."""
        name = f'{self.label} {self.topic}' if self.topic else self.label
        if self.topic is not None and self.count == 0:
            return [f'{name}: no messages received on {self.topic} yet']
        frame = self.frame()
        if frame is not None and poses.get(frame) is None:
            return [f'{name}: No transform from [{frame}] to [{fixed}]: '
                    f'{tree.why_not(frame, fixed)}']
        return []


class Grid(Display):
    kind, label = 'grid', 'Grid'

    def __init__(self, cells: int = 10, size: float = 1.0, **options: object) -> None:
        super().__init__(None, None, cells=cells, size=size, **options)


class TF(Display):
    """Every frame's axes and name, and an arrow to its parent; frames can be hidden."""

    kind, label = 'tf', 'TF'

    def __init__(self, scale: float = 1.0, **options: object) -> None:
        super().__init__(None, None, scale=scale, **options)


class RobotModel(Display):
    """The robot from its URDF (`/robot_description`), each link at its TF frame."""

    kind, label = 'robot_model', 'RobotModel'
    type_names = ('std_msgs/msg/String',)
    latched = True

    def __init__(self, topic: str = '/robot_description', prefix: str = '',
                 **options: object) -> None:
        super().__init__(topic, None, prefix=prefix, **options)
        self.prefix = prefix
        self.urdf: str | None = None
        self.links: list[str] = []
        self.root: str | None = None
        self.mesh_uris: list[str] = []  # read with the links, not again at each send
        self.error = ''
        self.meshes = MeshFiles()

    def _take(self, msg: Any) -> None:
        self.set_urdf(str(msg.data))

    def set_urdf(self, urdf: str) -> None:
        """Read the links and meshes of a URDF (call with the lock held, or before use)."""
        self.urdf = urdf
        self.meshes = MeshFiles()
        try:
            root = ET.fromstring(urdf)
        except ET.ParseError as err:
            self.error = (f'the URDF on {self.topic} does not parse ({err}); '
                          'fix: check it with `check_urdf` or `xacro` first')
            self.links, self.root, self.mesh_uris = [], None, []
            return
        self.error = ''
        self.mesh_uris = mesh_uris(root)
        self.links = [str(link.get('name')) for link in root.iter('link')]
        children = {str(j.find('child').get('link')) for j in root.iter('joint')  # type: ignore[union-attr]
                    if j.find('child') is not None}
        roots = [name for name in self.links if name not in children]
        self.root = roots[0] if roots else None

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        if self.urdf is None or self.error:
            return None
        if full:
            self.meshes.forget_sent()
        out.meshes.update(self.meshes.pack(self.mesh_uris, out.buffers))
        return {'urdf': self.urdf}

    def status(self, poses: dict[str, Pose | None], tree: FrameTree, fixed: str) -> list[str]:
        if self.count == 0 and self.urdf is None:
            return [f'RobotModel: nothing received on {self.topic} yet (robot_state_publisher '
                    'publishes it; start it, or the launch file that does)']
        if self.error:
            return [f'RobotModel: {self.error}']
        lines = []
        known = tree.frames()
        frames = [self.prefix + link for link in self.links]
        absent = [f for f in frames if poses.get(f) is None and f not in known
                  and f not in tree.rejected]
        if absent:
            names = ', '.join(f'[{f}]' for f in absent[:6])
            more = f' and {len(absent) - 6} more' if len(absent) > 6 else ''
            lines.append(
                f'No transform from {names}{more} to [{fixed}]: nothing publishes '
                f'{"this frame" if len(absent) == 1 else "these frames"} on /tf '
                '(robot_state_publisher publishes a moving joint only once /joint_states '
                'gives its position: run joint_state_publisher or robot_lab.joint_sliders()); '
                'drawn white at the origin')
        for frame in frames:
            if poses.get(frame) is None and frame not in absent:
                lines.append(f'No transform from [{frame}] to [{fixed}]: '
                             f'{tree.why_not(frame, fixed)}; drawn white at the origin')
        for uri, why in sorted(self.meshes.errors.items()):
            lines.append(f'RobotModel: {uri}: {why}')
        return lines


class LaserScan(Display):
    kind, label = 'laser_scan', 'LaserScan'
    type_names = ('sensor_msgs/msg/LaserScan',)

    def __init__(self, topic: str = '/scan', **options: object) -> None:
        super().__init__(topic, None, **options)
        self._msg: Any = None

    def _take(self, msg: Any) -> None:
        self._msg = msg

    def frame(self) -> str | None:
        return None if self._msg is None else str(self._msg.header.frame_id).lstrip('/')

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        msg = self._msg
        if msg is None:
            return None
        data: dict[str, object] = {
            'frame': self.frame(), 'angle_min': msg.angle_min,
            'angle_increment': msg.angle_increment, 'range_min': msg.range_min,
            'range_max': msg.range_max, 'ranges': out.buffer(_float32(msg.ranges))}
        if len(msg.intensities) == len(msg.ranges):
            data['intensities'] = out.buffer(_float32(msg.intensities))
        return data


def _float32(values: Any) -> bytes:
    """rclpy gives float32 arrays as array.array('f'): their bytes as they are."""
    if hasattr(values, 'tobytes') and getattr(values, 'typecode', 'f') == 'f':
        return bytes(values.tobytes())
    from array import array

    return array('f', values).tobytes()


class Markers(Display):
    """Marker and MarkerArray topics; also shapes given from Python (`set_markers`)."""

    kind, label = 'markers', 'Marker'
    type_names = ('visualization_msgs/msg/MarkerArray', 'visualization_msgs/msg/Marker')
    latched = True

    def __init__(self, topic: str | None = '/visualization_marker_array',
                 name: str | None = None, **options: object) -> None:
        super().__init__(topic, name, **options)
        self.items: dict[str, dict[str, object]] = {}
        self.expiry: dict[str, float] = {}
        self._ops: list[dict[str, object]] = []
        self._mesh_files = MeshFiles()

    def _take(self, msg: Any) -> None:
        for marker in getattr(msg, 'markers', [msg]):
            self._one(marker)

    def set_markers(self, markers: Iterable[Any]) -> None:
        """Draw these visualization_msgs/Marker messages (no topic needed): a world's
        walls, a goal, anything the kernel computes."""
        with self._lock:
            for marker in markers:
                self._one(marker)
            self.count += 1
            self._dirty = True

    def _one(self, m: Any) -> None:
        key = f'{m.ns}/{m.id}'
        action = int(m.action)
        if action == _DELETEALL:
            self.items = {k: v for k, v in self.items.items()
                          if m.ns and not k.startswith(f'{m.ns}/')}
            self._ops.append({'action': _DELETEALL, 'ns': m.ns})
            return
        if action == _DELETE:
            self.items.pop(key, None)
            self._ops.append({'action': _DELETE, 'key': key})
            return
        op: dict[str, object] = {
            'action': _ADD, 'key': key, 'type': int(m.type),
            'frame': str(m.header.frame_id).lstrip('/'), 'pose': list(_pose(m.pose)),
            'scale': [m.scale.x, m.scale.y, m.scale.z],
            'color': [m.color.r, m.color.g, m.color.b, m.color.a],
            'points': [v for p in m.points for v in (p.x, p.y, p.z)],
            'colors': [v for c in m.colors for v in (c.r, c.g, c.b, c.a)],
            'text': str(m.text), 'mesh': str(m.mesh_resource),
            'use_embedded': bool(m.mesh_use_embedded_materials)}
        self.items[key] = op
        self._ops.append(op)
        life = m.lifetime.sec + m.lifetime.nanosec * 1e-9
        if life > 0:
            self.expiry[key] = time.monotonic() + life
        else:
            self.expiry.pop(key, None)

    def _expire(self) -> None:
        now = time.monotonic()
        for key in [k for k, t in self.expiry.items() if t <= now]:
            del self.expiry[key]
            if self.items.pop(key, None) is not None:
                self._ops.append({'action': _DELETE, 'key': key})

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        ops = ([{'action': _DELETEALL, 'ns': ''}, *self.items.values()] if full else self._ops)
        self._ops = []
        meshes = [str(op['mesh']) for op in ops if op.get('type') == _MESH and op.get('mesh')]
        if meshes:
            out.meshes.update(self._mesh_files.pack(meshes, out.buffers))
        return {'ops': ops} if ops else None

    def data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        with self._lock:
            if self.expiry:
                self._expire()
                if self._ops:
                    self._dirty = True
        if full:
            self._mesh_files.forget_sent()
        return super().data(out, full)

    def frame(self) -> str | None:
        return None

    def status(self, poses: dict[str, Pose | None], tree: FrameTree, fixed: str) -> list[str]:
        lines = super().status(poses, tree, fixed) if self.topic else []
        with self._lock:
            frames = sorted({str(op['frame']) for op in self.items.values()})
        for frame in frames:
            if poses.get(frame) is None:
                lines.append(f'{self.label} {self.topic or self.id}: No transform from '
                             f'[{frame}] to [{fixed}]: {tree.why_not(frame, fixed)}')
        return lines


class Path(Display):
    kind, label = 'path', 'Path'
    type_names = ('nav_msgs/msg/Path',)

    def __init__(self, topic: str = '/plan', **options: object) -> None:
        super().__init__(topic, None, **options)
        self._frame: str | None = None
        self._points: list[float] = []

    def _take(self, msg: Any) -> None:
        self._frame = str(msg.header.frame_id).lstrip('/')
        self._points = [v for s in msg.poses
                        for v in (s.pose.position.x, s.pose.position.y, s.pose.position.z)]

    def frame(self) -> str | None:
        return self._frame

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        return None if self._frame is None else {'frame': self._frame, 'points': self._points}


class Odometry(Display):
    """The last `keep` poses an Odometry topic gave, each `position_tolerance` m or
    `angle_tolerance` rad from the one before (RViz's defaults: 100, 0.1, 0.1)."""

    kind, label = 'odometry', 'Odometry'
    type_names = ('nav_msgs/msg/Odometry',)

    def __init__(self, topic: str = '/odom', keep: int = 100, position_tolerance: float = 0.1,
                 angle_tolerance: float = 0.1, **options: object) -> None:
        super().__init__(topic, None, **options)
        self.keep = keep
        self.tolerances = (position_tolerance, angle_tolerance)
        self._frame: str | None = None
        self._poses: list[Pose] = []

    def _take(self, msg: Any) -> None:
        pose = _pose(msg.pose.pose)
        self._frame = str(msg.header.frame_id).lstrip('/')
        if self._poses:
            last = self._poses[-1]
            moved = math.dist(pose[:3], last[:3])
            dot = abs(sum(a * b for a, b in zip(pose[3:], last[3:], strict=True)))
            turned = 2.0 * math.acos(min(1.0, dot))
            if moved < self.tolerances[0] and turned < self.tolerances[1]:
                return
        self._poses = [*self._poses, pose][-self.keep:]

    def frame(self) -> str | None:
        return self._frame

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        if self._frame is None:
            return None
        return {'frame': self._frame, 'poses': [v for p in self._poses for v in p]}


class PoseStamped(Display):
    kind, label = 'pose', 'Pose'
    type_names = ('geometry_msgs/msg/PoseStamped',)

    def __init__(self, topic: str = '/goal_pose', **options: object) -> None:
        super().__init__(topic, None, **options)
        self._frame: str | None = None
        self._pose: Pose | None = None

    def _take(self, msg: Any) -> None:
        self._frame = str(msg.header.frame_id).lstrip('/')
        self._pose = _pose(msg.pose)

    def frame(self) -> str | None:
        return self._frame

    def _data(self, out: Outbox, full: bool) -> dict[str, object] | None:
        if self._pose is None:
            return None
        return {'frame': self._frame, 'poses': list(self._pose)}


# message type → the display that draws it (RViz's "By topic" list)
BY_TYPE: dict[str, type[Display]] = {
    name: cls for cls in (RobotModel, LaserScan, Markers, Path, Odometry, PoseStamped)
    for name in cls.type_names}
