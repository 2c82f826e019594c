"""`robot_lab.scene_view()`: the robot, its TF frames and sensor data in 3D, as RViz shows them.

The kernel takes `/tf`, `/tf_static` and each display's topic, resolves every frame's
newest pose in the fixed frame, and at the display rate sends the browser only the poses
and data that changed. The rate is 40 Hz: at RViz's 30, timer jitter and two messages
landing in one browser frame left 29.8 frames/s (`bench/bench_scene_view.py`). The
browser (three.js) places each display at its frame and draws a frame only when something
changed or the camera moved. With no frontend (nbval, CI) the view shows a matplotlib
picture of the frames instead.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from robot_lab.scene.camera import Vec3, camera_values, eye_and_target
from robot_lab.scene.displays import TF, Display, Grid, Markers, Outbox, RobotModel
from robot_lab.scene.frames import FrameTree, Pose
from robot_lab.scene.picture import frames_picture
from robot_lab.scene.subscriptions import (
    TF_TYPE,
    Subscriptions,
    display_for,
    display_qos,
    tf_qos,
    tf_transforms,
)
from robot_lab.widgets.live_view import LiveView
from robot_lab.widgets.output import owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import Widget
    from matplotlib.figure import Figure
    from rclpy.node import Node
    from rclpy.qos import QoSProfile

    from robot_lab.scene.canvas import SceneCanvas

__all__ = ['SceneView', 'scene_view']

# How often the status line is recomputed while only poses move (a link that lost its
# transform shows within this); a tree that changed updates it at once.
_STATUS_PERIOD = 0.5
# How often a view no page shows takes what arrived (nbval, a view scrolled away)
_IDLE_PERIOD = 0.1


class SceneView(LiveView):
    """The 3D view. `frames()` and `status` say what it shows (for checks and tests)."""

    def __init__(self, fixed_frame: str | None = None, topics: tuple[str, ...] = (),
                 robot_description: str | None = '/robot_description', rate: float = 40.0,
                 domain_id: int | None = None, headless_seconds: float | None = None,
                 height: int = 480, camera: tuple[Vec3, Vec3] | None = None) -> None:
        from robot_lab.rclpy_session import session

        super().__init__(rate, headless_seconds)
        self.height = int(height)
        self.session = session(domain_id)
        self.tree = FrameTree()
        self._lock = threading.Lock()
        self._fixed = fixed_frame or ''
        self._auto_fixed = not fixed_frame
        self.displays: dict[str, Display] = {}
        self._tf_dirty = False
        self._send_all = True  # the next tick sends everything (a view appeared)
        # the page's views by id: on screen, or scrolled out of sight (then nothing is sent)
        self._views_seen: set[str] = set()
        self._views_hidden: set[str] = set()
        self.ticks = 0
        self._wake = threading.Event()  # the view's thread: tick now
        self._resend_poses = False
        self._sent_poses: dict[str, Pose | None] = {}
        self._sent_version = -1
        self._status: list[str] = []
        self._status_at = 0.0
        self._added: list[Display] = []
        self._removed: list[str] = []
        self._thread: threading.Thread | None = None
        self._scene_canvas: SceneCanvas | None = None
        self._camera: list[float] = []
        if camera is not None:
            self.look_at(*camera)
        self.messages = 0  # messages sent to the browser
        # by display id, TF's as ' /tf' and ' /tf_static'; raw: the view reads the
        # transforms from the bytes (frames.parse_tf_message)
        self._subscriptions = Subscriptions(self._own_node(), self._closed)
        self._subscribe(' /tf', TF_TYPE, '/tf', tf_qos(static=False), self._on_tf, raw=True)
        self._subscribe(' /tf_static', TF_TYPE, '/tf_static', tf_qos(static=True),
                        self._on_tf_static, raw=True)
        self.add_display(Grid())
        if robot_description:
            self.add_display(RobotModel(robot_description))
        self.add_display(TF())
        for topic in topics:
            self.add(topic)
        owned_by_cell(self)
        self._thread = threading.Thread(target=self.log.guard(self._loop), daemon=True,
                                        name='robot_lab-scene')
        self._thread.start()

    # -- ROS -----------------------------------------------------------------------------
    def _own_node(self) -> Node:
        """A node of the view's own that no executor spins (`subscriptions` says why)."""
        return self.session.hidden_node(f'scene_{id(self):x}')

    def _subscribe(self, key: str, type_name: str, topic: str, qos: QoSProfile,
                   take: Callable[[Any], None], raw: bool = False) -> None:
        self._subscriptions.add(key, type_name, topic, qos, self.log.guard(take), raw)

    def _on_tf(self, raw: bytes, static: bool = False) -> None:
        transforms = tf_transforms(raw)
        changed = False
        with self._lock:
            for parent, child, pose in transforms:
                changed |= self.tree.put(parent, child, pose, static)
            if changed:
                self._tf_dirty = True

    def _on_tf_static(self, raw: bytes) -> None:
        self._on_tf(raw, static=True)

    def add(self, topic: str, display: str | type[Display] | None = None,
            **options: object) -> Display:
        """Show a topic, as RViz's "Add ▸ By topic": its display follows from its type
        (LaserScan, Marker/MarkerArray, Path, Odometry, PoseStamped), or name it."""
        topic = topic if topic.startswith('/') else '/' + topic
        types = dict(self.session.node.get_topic_names_and_types()).get(topic, [])
        return self.add_display(display_for(topic, types, display, options))

    def add_display(self, display: Display) -> Display:
        """Show a display built in Python (a world's shapes, say): subscribed if it has a
        topic, sent to the browser at the next tick."""

        if display.id in self.displays:
            self.remove(display.id)
        if display.topic is not None:
            self._subscribe(display.id, display.type_name, display.topic,
                            display_qos(self.session.node, display), display.take)
        with self._lock:
            self.displays[display.id] = display
            self._added.append(display)
        return display

    def show_markers(self, name: str, markers: Iterable[Any]) -> Markers:
        """Draw visualization_msgs/Marker messages made in Python, under the display
        `name` (a simulated world's walls and obstacles, a goal): no topic needed. Call it
        again to add, change (same ns and id) or delete (DELETE, DELETEALL) shapes."""
        display = self.displays.get(name)
        if not isinstance(display, Markers):
            display = Markers(None, name=name)
            self.add_display(display)
        display.set_markers(markers)
        return display

    def remove(self, display_id: str) -> None:
        with self._lock:
            self.displays.pop(display_id, None)
            self._removed.append(display_id)
        self._subscriptions.remove(display_id)

    # -- what it shows -------------------------------------------------------------------
    @property
    def fixed_frame(self) -> str:
        return self._fixed

    @fixed_frame.setter
    def fixed_frame(self, frame: str) -> None:
        with self._lock:
            self._fixed = frame.lstrip('/')
            self._auto_fixed = False
            self._resend_poses = True
        if self._scene_canvas is not None:
            self.canvas.fixed_frame = self._fixed

    def hide_frames(self, frames: Iterable[str] = ()) -> None:
        """Hide these TF frames' axes and names (RViz's TF display, its frames unticked);
        `hide_frames()` shows them all again."""
        self.canvas.hidden_frames = sorted({f.lstrip('/') for f in frames})

    @property
    def hidden_frames(self) -> list[str]:
        """The TF frames hidden in the view (ticked off there, or by `hide_frames`)."""
        return [] if self._scene_canvas is None else list(self._scene_canvas.hidden_frames)

    def frames(self) -> dict[str, Pose | None]:
        """Every TF frame's newest pose in the fixed frame (None: no transform to it)."""
        with self._lock:
            return self.tree.resolve(self._choose_fixed())

    @property
    def status(self) -> list[str]:
        """The lines under the picture: what is missing, and why."""
        with self._lock:
            return self._status_lines(self.tree.resolve(self._choose_fixed()))

    def _choose_fixed(self) -> str:
        """The fixed frame; by default the robot's root link, else the TF tree's root."""
        if self._auto_fixed and not self._fixed:
            robot = next((d for d in self.displays.values() if isinstance(d, RobotModel)
                          and d.root), None)
            if robot is not None and robot.root:
                self._fixed = robot.prefix + robot.root
            elif self.tree.edges:
                found = self.tree.root_of(min(self.tree.edges))
                self._fixed = found[0] if found else ''
        return self._fixed

    def _status_lines(self, poses: dict[str, Pose | None]) -> list[str]:
        fixed = self._fixed
        if not fixed:
            return ['Fixed frame: no TF frames yet (nothing publishes /tf or /tf_static)']
        lines = []
        if fixed not in poses:
            lines.append(f'Fixed Frame [{fixed}] does not exist')
        for display in list(self.displays.values()):
            lines.extend(display.status(poses, self.tree, fixed))
        lines.extend(f'TF: {why}' for why in self.tree.rejected.values())
        return lines or [f'{len(poses)} frames in [{fixed}]']

    def _picture_ready(self) -> bool:
        with self._lock:
            robot = next((d for d in self.displays.values() if isinstance(d, RobotModel)), None)
            if robot is None:
                return bool(self.tree.edges)
            poses = self.tree.resolve(self._choose_fixed())
            return bool(robot.links) and all(
                poses.get(robot.prefix + link) is not None for link in robot.links)

    def look_at(self, eye: Vec3, target: Vec3) -> None:
        """Put the camera at `eye`, looking at (and orbiting about) `target`, both in the
        fixed frame (RViz's Orbit view, set from code): a lesson shows what it is about
        without asking the student to orbit. Pages showing the view, and pages drawn later,
        move to it."""
        values = camera_values(eye, target)
        self._camera = values
        if self._scene_canvas is not None:
            self._scene_canvas.camera = values

    @property
    def camera(self) -> tuple[Vec3, Vec3] | None:
        """The eye and target `look_at` set (None: the view's first camera)."""
        return eye_and_target(self._camera)

    # -- the browser ---------------------------------------------------------------------
    @property
    def canvas(self) -> SceneCanvas:
        _ = self.widget
        assert self._scene_canvas is not None
        return self._scene_canvas

    @property
    def widget(self) -> Widget:
        if self._widget is None:
            from robot_lab.scene.canvas import SceneCanvas
            from robot_lab.widgets.canvas import kit_box

            canvas = SceneCanvas(height=self.height, fixed_frame=self._fixed,
                                 camera=self._camera)
            canvas.on_msg(self._on_msg)
            canvas.observe(self._on_fixed, names='fixed_frame')
            self._scene_canvas = canvas
            self._widget = kit_box([canvas, self.log.widget], max_width='960px')
        return self._widget

    def _on_msg(self, _widget: object, content: object, _buffers: object) -> None:
        if not isinstance(content, dict):
            return
        view = str(content.get('view', ''))
        with self._lock:
            if content.get('kind') == 'ready':
                self._send_all = True
            elif content.get('kind') == 'seen' and content.get('value'):
                self._views_hidden.discard(view)
                self._views_seen.add(view)
                self._resend_poses = True  # catch up on what moved while out of sight
            elif content.get('kind') == 'seen':
                self._views_seen.discard(view)
                self._views_hidden.add(view)
        self._wake.set()

    def _out_of_sight(self) -> bool:
        """Every view of it that spoke is scrolled away (or gone): the kernel keeps taking
        messages but sends nothing, and catches up when one is seen again."""
        with self._lock:
            return bool(self._views_hidden) and not self._views_seen

    def _on_fixed(self, change: dict[str, Any]) -> None:
        if change['new'] and change['new'] != self._fixed:
            self.fixed_frame = str(change['new'])

    def start(self) -> SceneView:
        """Show the view: its thread (taking messages since it was made) sends too."""
        _ = self.widget
        return self

    def _loop(self) -> None:
        due = time.monotonic()
        while True:
            # At the display rate while a page shows it; else 10 Hz, enough to keep /tf's
            # queue (100 deep) from overflowing and `frames()` current for checks.
            drawn = self._scene_canvas is not None and not self._out_of_sight()
            due += 1.0 / self.rate if drawn else _IDLE_PERIOD
            wait = due - time.monotonic()
            if wait < 0:  # fell behind (a busy host): skip, do not burst
                due, wait = time.monotonic(), 0.0
            if self._wake.wait(wait):  # a page appeared or came into sight, or closing
                self._wake.clear()
                due = time.monotonic()
            if self._closed.is_set():
                return
            self.tick()

    def tick(self) -> dict[str, object] | None:
        """Send the browser what changed since the last tick; returns the message sent."""
        self._subscriptions.take()
        self.ticks += 1
        if self._scene_canvas is None or self._out_of_sight():
            return None  # nothing shows it now: keep what is new for when something does
        out = Outbox()
        msg: dict[str, object] = {}
        with self._lock:
            full, self._send_all = self._send_all, False
            added, self._added = self._added, []
            removed, self._removed = self._removed, []
            tf_dirty, self._tf_dirty = self._tf_dirty or self._resend_poses, False
            every_pose, self._resend_poses = self._resend_poses or full, False
            before = self._fixed
            fixed = self._choose_fixed()
            every_pose |= fixed != before
            displays = list(self.displays.values())
            poses = self.tree.resolve(fixed) if (tf_dirty or every_pose) else None
            version = self.tree.version
            # the tree's edges change under _on_tf: copied here, under the lock
            tree = (self.tree.tree() if poses is not None
                    and (full or version != self._sent_version) else None)
        if full:
            msg.update(kind='reset', fixed=fixed, displays=[d.spec() for d in displays])
        else:
            if added:
                msg['add'] = [d.spec() for d in added]
            if removed:
                msg['remove'] = removed
        if fixed != before and self._scene_canvas is not None:
            self._scene_canvas.fixed_frame = fixed
        if every_pose and not full:
            msg['fixed'] = fixed  # the browser's menu follows a change made in Python
        if poses is not None:
            if every_pose:
                changed = poses
            else:
                missing = object()
                changed = {k: v for k, v in poses.items()
                           if self._sent_poses.get(k, missing) != v}
            if changed:
                msg['poses'] = {k: None if v is None else list(v) for k, v in changed.items()}
                self._sent_poses = poses
            if tree is not None:
                msg['tree'] = tree
                self._sent_version = version
        data = {}
        for display in displays:
            found = display.data(out, full or display in added)
            if found is not None:
                data[display.id] = found
        if data:
            msg['data'] = data
        if out.meshes:
            msg['meshes'] = out.meshes
        self._update_status(poses, urgent=full or 'tree' in msg or bool(data) or bool(added))
        if not msg or self._scene_canvas is None:
            return None
        msg.setdefault('kind', 'update')
        self._scene_canvas.send(msg, out.buffers or None)
        self.messages += 1
        return msg

    def _update_status(self, poses: dict[str, Pose | None] | None, urgent: bool) -> None:
        now = time.monotonic()
        if not urgent and now - self._status_at < _STATUS_PERIOD:
            return
        self._status_at = now
        with self._lock:
            lines = self._status_lines(poses if poses is not None
                                       else self.tree.resolve(self._fixed))
        self._status = lines
        canvas = self._scene_canvas  # made after the view's thread started, maybe
        if canvas is not None and list(canvas.status) != lines:
            canvas.status = lines

    # -- the static picture --------------------------------------------------------------
    def _figure(self) -> Figure:
        """The TF frames (axes and names) seen in 3D, with the status lines as a title."""
        with self._lock:
            fixed = self._choose_fixed()
            poses = self.tree.resolve(fixed)
            tree = self.tree.tree()
            lines = self._status_lines(poses)
        return frames_picture(fixed, poses, tree, lines)

    # -- closing -------------------------------------------------------------------------
    def _release(self) -> None:
        if self._scene_canvas is not None:
            self._scene_canvas.status = [*self._status, 'closed: no longer updated']
        self._wake.set()  # the thread sees `_closed` at once, not after its period
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self._subscriptions.close()

    def __repr__(self) -> str:
        with self._lock:
            frames = len(self.tree.frames())
        return (f'<SceneView fixed_frame={self._fixed!r}: {frames} frames, '
                f'displays {", ".join(self.displays)}>')


def scene_view(fixed_frame: str | None = None, topics: tuple[str, ...] | list[str] = (),
               robot_description: str | None = '/robot_description', rate: float = 40.0,
               domain_id: int | None = None, headless_seconds: float | None = None,
               height: int = 480, camera: tuple[Vec3, Vec3] | None = None) -> SceneView:
    """RViz in the notebook: `robot_lab.scene_view('base_link')` as a cell's result.

    Shows a grid, the robot from `robot_description` (each link at its TF frame; a link
    with no transform white at the origin, and the status line says why), every TF frame
    (tick one off in "TF frames"), and each topic in `topics` (LaserScan, Marker,
    MarkerArray, Path, Odometry, PoseStamped; `view.add('/scan')` adds one later). The
    fixed frame defaults to the robot's root link; pick another in the view's menu.
    Drag to orbit, right-drag (or shift-drag) to pan, scroll to zoom; `camera` (eye,
    target) or `view.look_at(eye, target)` places the camera from code.
    """
    return SceneView(fixed_frame, tuple(topics), robot_description, rate=rate,
                     domain_id=domain_id, headless_seconds=headless_seconds, height=height,
                     camera=camera)
