"""What a key does, as ros2/teleop_twist_keyboard (2.4.1, Jazzy) documents it; pure Python.

A motion key sets a direction (x, y, z, yaw) that stays until another key: the published
Twist is that direction times the current `speed` (linear) and `turn` (angular). Shifted
keys strafe (holonomic), `t`/`b` go up and down, the speed keys scale `speed` and/or
`turn` by 10 % and keep the direction, and any other key stops. Written for robot_lab
from upstream's README and behaviour; no upstream code.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

__all__ = ['BANNER', 'LAYOUT', 'MOVES', 'QUIT', 'SPEEDS', 'Drive', 'Velocity',
           'speed_line', 'twist_message']

# The text upstream prints when it starts (and again after every 15 speed changes).
BANNER = """
This node takes keypresses from the keyboard and publishes them
as Twist/TwistStamped messages. It works best with a US keyboard layout.
---------------------------
Moving around:
   u    i    o
   j    k    l
   m    ,    .

For Holonomic mode (strafing), hold down the shift key:
---------------------------
   U    I    O
   J    K    L
   M    <    >

t : up (+z)
b : down (-z)

anything else : stop

q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%

CTRL-C to quit
"""

QUIT = '\x03'  # CTRL-C, read as a key: the terminal is raw, so it sends no SIGINT

Direction = tuple[int, int, int, int]  # x, y, z (linear) and yaw, each -1, 0 or 1

# The pad as it sits on the keyboard: plain keys drive and turn (k is "stop": it is in no
# table, like every other key), shifted ones strafe. Backing up, m turns right and . left.
LAYOUT: tuple[tuple[str, ...], ...] = (
    ('u', 'i', 'o'), ('j', 'k', 'l'), ('m', ',', '.'),
)
MOVES: dict[str, Direction] = {
    'u': (1, 0, 0, 1), 'i': (1, 0, 0, 0), 'o': (1, 0, 0, -1),
    'j': (0, 0, 0, 1), 'l': (0, 0, 0, -1),
    'm': (-1, 0, 0, -1), ',': (-1, 0, 0, 0), '.': (-1, 0, 0, 1),
    'U': (1, 1, 0, 0), 'I': (1, 0, 0, 0), 'O': (1, -1, 0, 0),
    'J': (0, 1, 0, 0), 'L': (0, -1, 0, 0),
    'M': (-1, 1, 0, 0), '<': (-1, 0, 0, 0), '>': (-1, -1, 0, 0),
    't': (0, 0, 1, 0), 'b': (0, 0, -1, 0),
}
# key -> factors for (speed, turn)
SPEEDS: dict[str, tuple[float, float]] = {
    'q': (1.1, 1.1), 'z': (0.9, 0.9),
    'w': (1.1, 1.0), 'x': (0.9, 1.0),
    'e': (1.0, 1.1), 'c': (1.0, 0.9),
}
STOP: Direction = (0, 0, 0, 0)


class Velocity(NamedTuple):
    """A Twist's non-zero parts: linear x, y, z (m/s) and angular z (rad/s)."""

    x: float
    y: float
    z: float
    yaw: float


def speed_line(speed: float, turn: float) -> str:
    """The line upstream prints at start and after each speed change (Python's repr of
    the floats: two q presses from 0.5 show 0.6050000000000001, as upstream's do)."""
    return f'currently:\tspeed {speed}\tturn {turn} '


@dataclass
class Drive:
    """The keyboard's state: the held direction and the two speeds."""

    speed: float = 0.5
    turn: float = 1.0
    direction: Direction = STOP
    speed_changes: int = 0

    def press(self, key: str) -> bool:
        """Apply one key; True when it changed the speeds (upstream then prints them)."""
        factors = SPEEDS.get(key)
        if factors is not None:
            self.speed *= factors[0]
            self.turn *= factors[1]
            self.speed_changes += 1
            return True
        self.direction = MOVES.get(key, STOP)
        return False

    def stop(self) -> None:
        self.direction = STOP

    @property
    def velocity(self) -> Velocity:
        x, y, z, yaw = self.direction
        return Velocity(x * self.speed, y * self.speed, z * self.speed, yaw * self.turn)


def twist_message(velocity: Velocity, stamped: bool = False, frame_id: str = '',
                  stamp: Any = None) -> Any:
    """A geometry_msgs Twist, or a TwistStamped with `stamp` and `frame_id` in its header."""
    from geometry_msgs.msg import Twist, TwistStamped

    twist = Twist()
    twist.linear.x = float(velocity.x)
    twist.linear.y = float(velocity.y)
    twist.linear.z = float(velocity.z)
    twist.angular.z = float(velocity.yaw)
    if not stamped:
        return twist
    message = TwistStamped(twist=twist)
    message.header.frame_id = frame_id
    if stamp is not None:
        message.header.stamp = stamp
    return message
