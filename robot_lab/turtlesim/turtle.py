"""One turtle, as turtlesim's Turtle class behaves: commands, pen, teleports, rotation goals.

Pure Python with no ROS in it, so the behaviour the tutorials rely on is tested directly:
a command holds for 1 s, walls clamp with turtlesim's warning, a rotation goal turns at
1 rad/s until within 0.02 rad, and a velocity command aborts it. The world is turtlesim's
11.09 m square, y up; the image below it is y down, 45 px to the metre.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple, Protocol

from robot_lab.turtlesim.path_image import METER, SIZE, PathImage

__all__ = ['CANVAS', 'DEFAULT_PEN', 'Logger', 'Pen', 'RotateGoal', 'Segment', 'Turtle',
           'TurtlePose', 'normalize_angle']

CANVAS = (SIZE - 1) / METER  # 11.0889 m: the world's width and height
COMMAND_TIMEOUT = 1.0  # seconds a cmd_vel keeps the turtle moving
ROTATE_TOLERANCE = 0.02  # rad: a rotation goal is reached
DEFAULT_PEN = (0xb3, 0xb8, 0xff)


class Logger(Protocol):
    def info(self, message: str) -> object: ...
    def warning(self, message: str) -> object: ...
    def error(self, message: str) -> object: ...


def normalize_angle(angle: float) -> float:
    """Into [-π, π), as turtlesim's normalizeAngle."""
    return angle - 2 * math.pi * math.floor((angle + math.pi) / (2 * math.pi))


class TurtlePose(NamedTuple):
    """turtlesim/msg/Pose's fields."""

    x: float
    y: float
    theta: float
    linear_velocity: float
    angular_velocity: float


class Segment(NamedTuple):
    """A pen stroke in world metres (y up), with its colour and width in pixels."""

    x0: float
    y0: float
    x1: float
    y1: float
    r: int
    g: int
    b: int
    width: int


@dataclass
class Pen:
    r: int = DEFAULT_PEN[0]
    g: int = DEFAULT_PEN[1]
    b: int = DEFAULT_PEN[2]
    width: int = 3
    on: bool = True


@dataclass
class RotateGoal:
    """A rotate_absolute goal in progress; the action server waits on `done`."""

    theta: float
    start: float
    is_canceling: Callable[[], bool] = lambda: False
    on_feedback: Callable[[float], None] = lambda remaining: None
    on_finish: Callable[[str], None] = lambda outcome: None
    outcome: str | None = None  # 'succeeded' | 'canceled' | 'aborted'
    delta: float = 0.0
    done: threading.Event = field(default_factory=threading.Event)

    def finish(self, outcome: str) -> None:
        self.outcome = outcome
        self.done.set()
        self.on_finish(outcome)


@dataclass
class _Teleport:
    x: float
    y: float
    theta: float
    linear: float
    relative: bool


class Turtle:
    """Position in metres (y up), heading in radians; commands, pen and pending requests."""

    def __init__(self, name: str, x: float, y: float, theta: float, image: int = 0,
                 now: float = 0.0, logger: Logger | None = None) -> None:
        self.name = name
        self.x, self.y, self.theta = float(x), float(y), float(theta)
        self.image = image
        self.vx = self.vy = self.w = 0.0
        self.pen = Pen()
        self.last_command = now
        self.goal: RotateGoal | None = None
        self.logger = logger
        self._teleports: list[_Teleport] = []
        self._lock = threading.Lock()

    # -- requests (from subscriptions and services, any thread) -------------------------
    def command(self, linear_x: float, linear_y: float, angular_z: float, now: float,
                holonomic: bool = False) -> None:
        """A cmd_vel: held for a second; aborts a rotation goal in progress."""
        with self._lock:
            self.last_command = now
            self.vx = float(linear_x)
            if holonomic:
                self.vy = float(linear_y)
            self.w = float(angular_z)
            if self.goal is not None:
                self._warn('Velocity command received during rotation goal. Aborting goal')
                self.goal.finish('aborted')
                self.goal = None

    def set_pen(self, r: int, g: int, b: int, width: int, off: bool) -> None:
        with self._lock:
            if off:
                self.pen.on = False
                return
            # a new QPen: width 0 keeps Qt's default width of 1
            self.pen = Pen(r, g, b, width if width != 0 else 1, True)

    def teleport_absolute(self, x: float, y: float, theta: float) -> None:
        with self._lock:
            self._teleports.append(_Teleport(x, y, theta, 0.0, False))

    def teleport_relative(self, linear: float, angular: float) -> None:
        with self._lock:
            self._teleports.append(_Teleport(0.0, 0.0, angular, linear, True))

    def rotate(self, goal: RotateGoal) -> None:
        """Accept a rotate_absolute goal; one still running is aborted."""
        with self._lock:
            if self.goal is not None:
                self._warn('Rotation goal received before a previous goal finished. '
                           'Aborting previous goal')
                self.goal.finish('aborted')
            goal.start = self.theta
            self.goal = goal

    def abandon(self) -> None:
        """The turtle is gone (kill/reset): a goal in progress ends, aborted."""
        with self._lock:
            if self.goal is not None:
                self.goal.finish('aborted')
                self.goal = None

    # -- one frame --------------------------------------------------------------------
    def update(self, dt: float, now: float, image: PathImage) -> tuple[
            TurtlePose, tuple[int, int, int], list[Segment]]:
        """Advance one frame: teleports, the rotation goal, the timeout, motion, walls.

        Returns the pose, the colour under the turtle (read before this frame's own stroke
        is drawn, as turtlesim does) and the strokes the pen drew.
        """
        with self._lock:
            strokes: list[Segment] = []
            for request in self._teleports:
                old = (self.x, self.y)
                if request.relative:
                    self.theta += request.theta
                    self.x += math.cos(self.theta) * request.linear
                    self.y += math.sin(self.theta) * request.linear
                else:
                    self.x = request.x
                    self.y = min(request.y, CANVAS)
                    self.theta = request.theta
                self._stroke(old, image, strokes)
            self._teleports.clear()
            self._rotate_step(now)
            if now - self.last_command > COMMAND_TIMEOUT:
                self.vx = self.vy = self.w = 0.0
            old = (self.x, self.y)
            self.theta = normalize_angle(self.theta + self.w * dt)
            c, s = math.cos(self.theta), math.sin(self.theta)
            self.x += (c * self.vx - s * self.vy) * dt
            self.y += (s * self.vx + c * self.vy) * dt
            if not (0 <= self.x <= CANVAS and 0 <= self.y <= CANVAS):
                self._warn(f'Oh no! I hit the wall! (Clamping from [x={self.x:f}, '
                           f'y={CANVAS - self.y:f}])')
            self.x = min(max(self.x, 0.0), CANVAS)
            self.y = min(max(self.y, 0.0), CANVAS)
            pose = TurtlePose(self.x, self.y, self.theta, math.hypot(self.vx, self.vy),
                              self.w)
            colour = self.color(image)
            if (self.x, self.y) != old:
                self._stroke(old, image, strokes)
            return pose, colour, strokes

    def color(self, image: PathImage) -> tuple[int, int, int]:
        """What color_sensor reports: the trail's pixel under the turtle."""
        return image.pixel(self.x * METER, (CANVAS - self.y) * METER)

    def _rotate_step(self, now: float) -> None:
        goal = self.goal
        if goal is None:
            return
        if goal.is_canceling():
            if self.logger is not None:
                self.logger.info('Rotation goal canceled')
            goal.finish('canceled')
            self.goal = None
            self.vx = self.vy = self.w = 0.0
            return
        theta = normalize_angle(goal.theta)
        remaining = normalize_angle(theta - self.theta)
        goal.delta = normalize_angle(goal.start - self.theta)
        goal.on_feedback(remaining)
        if abs(normalize_angle(self.theta - theta)) < ROTATE_TOLERANCE:
            if self.logger is not None:
                self.logger.info('Rotation goal completed successfully')
            goal.finish('succeeded')
            self.goal = None
            self.vx = self.vy = self.w = 0.0
        else:
            self.vx = self.vy = 0.0
            self.w = -1.0 if remaining < 0.0 else 1.0
            self.last_command = now

    def _stroke(self, old: tuple[float, float], image: PathImage,
                strokes: list[Segment]) -> None:
        if not self.pen.on:
            return
        pen = self.pen
        image.line(old[0] * METER, (CANVAS - old[1]) * METER, self.x * METER,
                   (CANVAS - self.y) * METER, (pen.r, pen.g, pen.b), pen.width)
        strokes.append(Segment(old[0], old[1], self.x, self.y, pen.r, pen.g, pen.b,
                               pen.width))

    def _warn(self, message: str) -> None:
        if self.logger is not None:
            self.logger.warning(message)
