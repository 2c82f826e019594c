"""turtlesim's frame: the turtles by name, the trails' image, spawn/kill/clear/reset.

As TurtleFrame does: turtle1 starts in the middle (5.544445, 5.544445) facing east; a
spawn without a name takes the next free `turtleN`; reset removes every turtle, restarts
the count and clears the trails; every frame moves each turtle by the frame period (16 ms),
however late the frame is. No ROS here: the node (`turtlesim.node`) wraps it.
"""

from __future__ import annotations

import random
import struct
import threading
from collections.abc import Callable
from typing import NamedTuple

from robot_lab.turtlesim.path_image import PathImage
from robot_lab.turtlesim.turtle import CANVAS, Logger, Segment, Turtle, TurtlePose

__all__ = ['FRAME_PERIOD', 'IMAGES', 'TurtleState', 'World']

FRAME_PERIOD = 0.016  # turtlesim's update timer: 16 ms
IMAGES = 10  # turtle pictures turtlesim chooses from at random


class TurtleState(NamedTuple):
    """One turtle after a frame: what its pose and color_sensor topics publish."""

    name: str
    pose: TurtlePose
    color: tuple[int, int, int]
    image: int


class World:
    """The frame's state; every method is safe to call from any thread."""

    def __init__(self, logger: Logger | None = None, seed: int | None = None,
                 on_spawn: Callable[[Turtle], None] | None = None,
                 on_kill: Callable[[Turtle], None] | None = None) -> None:
        self.logger = logger
        self.image = PathImage()
        self.turtles: dict[str, Turtle] = {}
        self.on_spawn = on_spawn
        self.on_kill = on_kill
        self._ids = 0
        self._random = random.Random(seed)
        self._lock = threading.RLock()

    def start(self, now: float = 0.0) -> Turtle:
        """The first turtle, in the middle of the world."""
        turtle = self.spawn('', CANVAS / 2.0, CANVAS / 2.0, 0.0, now)
        assert turtle is not None
        return turtle

    def spawn(self, name: str, x: float, y: float, theta: float,
              now: float = 0.0) -> Turtle | None:
        """A new turtle; None (and turtlesim's error) when the name is taken."""
        x, y, theta = (_float32(v) for v in (x, y, theta))  # spawnTurtle takes floats
        with self._lock:
            if not name:
                while True:
                    self._ids += 1
                    name = f'turtle{self._ids}'
                    if name not in self.turtles:
                        break
            elif name in self.turtles:
                if self.logger is not None:
                    self.logger.error(f'A turtle named [{name}] already exists')
                return None
            turtle = Turtle(name, x, y, theta, self._random.randrange(IMAGES), now,
                            self.logger)
            self.turtles[name] = turtle
            if self.on_spawn is not None:
                self.on_spawn(turtle)
        if self.logger is not None:
            self.logger.info(f'Spawning turtle [{name}] at x=[{x:f}], y=[{y:f}], '
                             f'theta=[{theta:f}]')
        return turtle

    def kill(self, name: str) -> bool:
        with self._lock:
            turtle = self.turtles.pop(name, None)
            if turtle is None:
                if self.logger is not None:
                    self.logger.error(
                        f'Tried to kill turtle [{name}], which does not exist')
                return False
            self._remove(turtle)
        return True

    def clear(self) -> None:
        if self.logger is not None:
            self.logger.info('Clearing turtlesim.')
        with self._lock:
            self.image.clear()

    def reset(self, now: float = 0.0) -> None:
        if self.logger is not None:
            self.logger.info('Resetting turtlesim.')
        with self._lock:
            for turtle in list(self.turtles.values()):
                self._remove(turtle)
            self.turtles.clear()
            self._ids = 0
            self.start(now)
            self.image.clear()

    def get(self, name: str) -> Turtle | None:
        with self._lock:
            return self.turtles.get(name)

    def scene(self) -> list[tuple[str, float, float, float, int]]:
        """Every turtle's name, x, y, theta and picture, as a window would draw them."""
        with self._lock:
            return [(t.name, t.x, t.y, t.theta, t.image) for t in self.turtles.values()]

    def picture(self) -> bytes:
        """The trails so far, as a PNG."""
        with self._lock:
            return self.image.png()

    def step(self, now: float, dt: float = FRAME_PERIOD) -> tuple[list[TurtleState],
                                                                  list[Segment]]:
        """One frame: every turtle moves; returns their states and the new pen strokes."""
        states: list[TurtleState] = []
        strokes: list[Segment] = []
        with self._lock:
            for turtle in list(self.turtles.values()):
                pose, colour, drawn = turtle.update(dt, now, self.image)
                strokes.extend(drawn)
                states.append(TurtleState(turtle.name, pose, colour, turtle.image))
        return states, strokes

    def _remove(self, turtle: Turtle) -> None:
        turtle.abandon()
        if self.on_kill is not None:
            self.on_kill(turtle)


def _float32(value: float) -> float:
    return float(struct.unpack('f', struct.pack('f', value))[0])
