"""See the robot move: its 2-D pose integrated from the velocity commands on a Twist topic.

The controller's decisions become a path on the floor, not only log lines. Each command
`(v, ω)` is held until the next one arrives, as a differential-drive base does, but at most
`hold` seconds (a base stops when commands stop). The browser draws the pose and its trail;
with no frontend (nbval, CI) the view collects for a bounded time and shows a picture.
"""

from __future__ import annotations

import itertools
import math
import threading
import time
from collections import deque
from typing import TYPE_CHECKING, NamedTuple

from robot_lab.widgets.live_view import PICTURE_SPAN, LiveView
from robot_lab.widgets.output import owned_by_cell

if TYPE_CHECKING:
    from geometry_msgs.msg import Twist, TwistStamped
    from ipywidgets import Widget
    from matplotlib.figure import Figure
    from rclpy.subscription import Subscription

    from robot_lab.widgets.canvas import Payload

__all__ = ['Pose', 'RobotView', 'robot_view']

_TWIST = 'geometry_msgs/msg/Twist'
_STAMPED = 'geometry_msgs/msg/TwistStamped'


class Pose(NamedTuple):
    """Where the robot is: metres from its start, heading in radians (counter-clockwise)."""

    x: float
    y: float
    theta: float


def integrate(pose: Pose, v: float, w: float, dt: float) -> Pose:
    """The pose after driving at (v, ω) for dt seconds (an exact arc, a line when ω ≈ 0)."""
    x, y, th = pose
    if abs(w) < 1e-9:
        return Pose(x + v * dt * math.cos(th), y + v * dt * math.sin(th), th)
    radius = v / w
    th2 = th + w * dt
    return Pose(x + radius * (math.sin(th2) - math.sin(th)),
                y - radius * (math.cos(th2) - math.cos(th)), th2)


class RobotView(LiveView):
    """The robot's pose from `topic`'s commands; `.pose`, `.path` and `.count` for checks."""

    headless_default = (3.0, 1.5)

    def __init__(self, topic: str = '/cmd_vel', hold: float = 0.5, rate: float = 20.0,
                 domain_id: int | None = None, headless_seconds: float | None = None,
                 height: int = 360) -> None:
        from robot_lab.rclpy_session import session

        super().__init__(rate, headless_seconds)
        self.topic = topic if topic.startswith('/') else '/' + topic
        self.hold = float(hold)
        self.height = int(height)
        self.count = 0
        self._pose = Pose(0.0, 0.0, 0.0)
        self._twist = (0.0, 0.0)
        self._first: float | None = None
        self._last: float | None = None
        self._path: deque[Pose] = deque([self._pose], maxlen=20_000)
        self._pending: list[float] = []
        self._lock = threading.Lock()
        self.session = session(domain_id)
        self._subscription = self._subscribe()
        owned_by_cell(self)

    def _subscribe(self) -> Subscription:
        from rclpy.qos import qos_profile_sensor_data

        from robot_lab.messages import message_class

        types = dict(self.session.node.get_topic_names_and_types())
        stamped = _STAMPED in types.get(self.topic, [])
        cls = message_class(_STAMPED if stamped else _TWIST)
        callback = self.log.guard(self._on_twist)
        # Best effort matches reliable and best-effort publishers alike.
        return self.session.run_in_executor(lambda: self.session.node.create_subscription(
            cls, self.topic, callback, qos_profile_sensor_data))

    def _on_twist(self, msg: Twist | TwistStamped) -> None:
        twist = getattr(msg, 'twist', msg)  # TwistStamped carries its Twist inside
        now = time.monotonic()
        with self._lock:
            if self._last is not None:
                dt = min(now - self._last, self.hold)
                self._pose = integrate(self._pose, *self._twist, dt)
                self._path.append(self._pose)
                self._pending.extend(self._pose)
            if self._first is None:
                self._first = now
            self._last = now
            self._twist = (float(twist.linear.x), float(twist.angular.z))
            self.count += 1

    def _picture_ready(self) -> bool:
        """The robot has driven on commands for PICTURE_SPAN seconds (a path, not a dot)."""
        with self._lock:
            return (self._first is not None and self._last is not None
                    and self._last - self._first >= PICTURE_SPAN)

    # -- data ------------------------------------------------------------------------
    @property
    def pose(self) -> Pose:
        with self._lock:
            return self._pose

    @property
    def path(self) -> list[Pose]:
        """Every pose so far, from the start (0, 0, 0)."""
        with self._lock:
            return list(self._path)

    def distance(self) -> float:
        """How far the robot has driven along its path, in metres."""
        path = self.path
        return sum(math.dist(a[:2], b[:2]) for a, b in itertools.pairwise(path))

    def wait_for_motion(self, metres: float = 0.05, timeout: float = 5.0) -> bool:
        """Block until the robot has driven `metres` (or the timeout); True if it has."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.distance() >= metres:
                return True
            self._closed.wait(0.05)
        return False

    def reset(self) -> None:
        """Put the robot back at (0, 0) facing +x and forget its trail."""
        with self._lock:
            self._pose = Pose(0.0, 0.0, 0.0)
            self._path = deque([self._pose], maxlen=20_000)
            self._pending = []
        if self._feed is not None:
            self._feed.reset()

    # -- the browser view ------------------------------------------------------------
    def _full(self) -> Payload:
        with self._lock:
            self._pending = []
            poses = [value for pose in self._path for value in pose]
            return {'kind': 'reset', 'poses': poses, 'twist': list(self._twist),
                    'count': self.count}

    def _new(self) -> Payload | None:
        with self._lock:
            if not self._pending:
                return None
            poses, self._pending = self._pending, []
            return {'kind': 'append', 'poses': poses, 'twist': list(self._twist),
                    'count': self.count}

    @property
    def widget(self) -> Widget:
        """The live view: the floor seen from above, the trail, the robot and its command."""
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import Feed, PoseCanvas

            canvas = PoseCanvas(config={'topic': self.topic, 'height': self.height})
            self._canvas = canvas
            self._feed = Feed(canvas, self._full, self._new, self.rate, self.log.guard)
            reset = widgets.Button(description='Reset', icon='undo',
                                   tooltip='put the robot back at the origin',
                                   layout=widgets.Layout(width='7em'))
            reset.on_click(lambda _b: self.reset())
            self._widget = widgets.VBox([reset, canvas, self.log.widget],
                                        layout=widgets.Layout(max_width='960px'))
            self._widget.add_class('robot-lab-widget')
        return self._widget

    def _figure(self) -> Figure:
        """The trail and the robot, seen from above."""
        from matplotlib.figure import Figure
        from matplotlib.patches import Circle, FancyArrow

        path, pose = self.path, self.pose
        fig = Figure(figsize=(6.0, 4.0), dpi=100)
        ax = fig.subplots()
        ax.plot([p.x for p in path], [p.y for p in path], color='#56B4E9', linewidth=2)
        xs = [p.x for p in path] + [-1.0, 1.0]
        ys = [p.y for p in path] + [-1.0, 1.0]
        size = max(max(xs) - min(xs), max(ys) - min(ys)) + 1.0
        radius = 0.03 * size
        ax.add_patch(Circle((pose.x, pose.y), radius, color='#0072B2'))
        ax.add_patch(FancyArrow(pose.x, pose.y, 1.6 * radius * math.cos(pose.theta),
                                1.6 * radius * math.sin(pose.theta), width=radius / 3,
                                color='#E69F00'))
        ax.set_xlim(min(xs) - 0.5, min(xs) - 0.5 + size)
        ax.set_ylim(min(ys) - 0.5, min(ys) - 0.5 + size)
        ax.set_aspect('equal', adjustable='box')  # the square limits kept, no warning
        ax.grid(True, color='#e5e5e5')
        ax.set_xlabel('x (m)', fontsize=9)
        ax.set_ylabel('y (m)', fontsize=9)
        ax.set_title(f'{self.topic}: x {pose.x:.2f} m, y {pose.y:.2f} m, '
                     f'θ {math.degrees(pose.theta):.0f}° ({self.count} messages)',
                     fontsize=10, loc='left')
        fig.tight_layout()
        return fig

    def _release(self) -> None:
        super()._release()
        subscription = self._subscription
        self.session.run_in_executor(
            lambda: self.session.node.destroy_subscription(subscription))

    def __repr__(self) -> str:
        x, y, th = self.pose
        return (f'<RobotView {self.topic}: x={x:.2f} m, y={y:.2f} m, '
                f'theta={math.degrees(th):.0f} deg, {self.count} messages>')


def robot_view(topic: str = '/cmd_vel', hold: float = 0.5, domain_id: int | None = None,
               headless_seconds: float | None = None) -> RobotView:
    """Draw the robot driven by a Twist topic: `robot_lab.robot_view('/cmd_vel')`.

    The pose starts at (0, 0) facing +x and integrates each command (linear.x, angular.z),
    held at most `hold` seconds. Shown as a cell's result it draws live in JupyterLab.
    """
    return RobotView(topic, hold=hold, domain_id=domain_id, headless_seconds=headless_seconds)
