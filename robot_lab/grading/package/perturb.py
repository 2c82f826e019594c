"""Does the controller follow its input? The grader drives the sensor topic itself.

Watching a running system cannot tell a controller that computes its command from the
reading from one that publishes `linear.x = 0.5` forever, nor an honest controller whose
output is saturated from a broken one. So, with the student's sensor paused (its process
stopped, or the system relaunched with the sensor remapped away), the grader publishes
messages of the sensor's type on the sensor's topic at three levels spanning the range
the sensor itself produced — low, high, low — and reads the controller's commands at each.
Every field of the command is read, whatever its type: numbers, booleans, strings, arrays
and nested messages (a Twist, a Bool lamp switch, an Int32 level, a custom message). The
controller follows its input when some field changes with it: a number that moves one way
from low to high and back the other way from high to low, or a boolean or a word that
flips at high and flips back at low (a lamp on below a threshold, a state 'OPEN'/'CLOSED').
An input-ignoring controller (constant, or drifting with time) does not; a saturated but
responsive one does.

Each level is read once the controller has answered it, not after a fixed time: on a
loaded host a controller's commands can trail its input by more than any fixed window
(a queue of older readings still to work through), so a level's commands are the first
steady run of them that differs from the previous level's, and a level that brings no
change is read after `_PATIENCE` seconds.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from robot_lab.grading.package.roles import Observation, Roles, TopicSeen

if TYPE_CHECKING:
    from robot_lab.grading.package.bridge import Bridge
    from robot_lab.rclpy_session import Session

__all__ = ['Response', 'Value', 'command_fields', 'drive_controller']

_RATE = 20.0  # Hz the grader publishes at
_SAMPLES = 5  # commands read per level, from the first one that answered it
_PATIENCE = 2.5  # s a level is held for a command that differs from the last level's
# s to wait for the controller's subscription to match the grader's publisher; discovery
# can take seconds on a loaded host, and a match that never comes is the grader's fault
_MATCH = 10.0
_SKIP = ('stamp', 'sec', 'nanosec', 'frame_id', 'seq')


# One command seen: field path -> its number, its truth value or its text (a lamp's
# switch is a bool, a command may be a word)
Value = float | bool | str
Sample = dict[str, Value]
_ITEMS = 64  # array items read per array field

@dataclass
class Response:
    """What the controller did when the grader drove its input."""

    tested: bool
    follows: bool = False
    how: str = ''  # how the sensor was taken out of the loop
    levels: list[tuple[float, Sample, int]] = field(default_factory=list)
    why: str = ''  # why it was not tested
    fault: str = ''  # the grader's own failure while driving it (not the controller's)

    def changed(self) -> list[str]:
        """The command fields that took more than one value across the levels."""
        keys = {k for _, outputs, _ in self.levels for k in outputs}
        return sorted(k for k in keys
                      if len({repr(outputs.get(k)) for _, outputs, _ in self.levels}) > 1)

    def table(self) -> str:
        """One line per level, the fields that moved between levels first, then those
        that are not zero (a Twist's `linear.x`, not its three `angular` zeros)."""
        def rank(key: str) -> tuple[bool, bool, str]:
            values = [outputs.get(key) for _, outputs, _ in self.levels]
            return len({repr(v) for v in values}) == 1, not any(values), key

        keys = sorted({k for _, outputs, _ in self.levels for k in outputs}, key=rank)
        shown_keys = max(3, min(len(self.changed()), 6))
        rows = []
        for level, outputs, count in self.levels:
            shown = ', '.join(f'{k} = {_show(v)}' for k in keys[:shown_keys]
                              if (v := outputs.get(k)) is not None) or '—'
            still = ' (none new: the last one stands)' if not count and outputs else ''
            rows.append(f'- input {level:.3g} → {count} command(s): {shown}{still}')
        return '\n'.join(rows)


def _show(value: Value) -> str:
    if isinstance(value, bool):
        return str(value)
    return f'{value:.3g}' if isinstance(value, float) else repr(value)


def _leaves(data: object) -> Iterator[tuple[str, float]]:
    """Numeric leaves of a message dict ('linear.x', 'ranges[0]'), stamps left out."""
    for key, value in command_fields(data):
        if not isinstance(value, bool | str):
            yield key, float(value)


def _varying(values: list[dict[str, object]]) -> tuple[set[str], float, float]:
    """The sensor's numeric fields that changed (all of them if none did) and the range
    they covered (a span around a constant reading). A sensor with no number (a door
    contact's Bool) has its booleans driven instead: levels 0 and 1 are False and True."""
    seen: dict[str, list[float]] = {}
    for data in values:
        for key, value in _leaves(data):
            seen.setdefault(key, []).append(value)
    if not seen:
        flags = {k for data in values for k, v in command_fields(data) if isinstance(v, bool)}
        if flags:
            return flags, 0.0, 1.0
    keys = {k for k, vs in seen.items() if max(vs) - min(vs) > 1e-9} or set(seen)
    numbers = [v for k in keys for v in seen[k]]
    low, high = (min(numbers), max(numbers)) if numbers else (0.0, 1.0)
    if math.isclose(low, high, abs_tol=1e-9):
        low, high = (low * 0.5, low * 1.5) if low else (-1.0, 1.0)
    return keys, low, high


def _wider(low: float, high: float) -> tuple[float, float]:
    """A range around (low, high) several times as wide, keeping the sign of a positive
    reading (a distance stays a distance)."""
    if low > 0:
        return low * 0.25, high * 4.0
    span = max(high - low, abs(high), abs(low), 1.0)
    return low - 2 * span, high + 2 * span


def _set_level(data: object, keys: set[str], level: float, prefix: str = '') -> object:
    """The template message with the varying numeric fields set to `level`."""
    if isinstance(data, dict):
        return {k: (v if k in _SKIP else _set_level(v, keys, level, f'{prefix}{k}.'))
                for k, v in data.items()}
    if isinstance(data, list):
        return [_set_level(v, keys, level, f'{prefix[:-1]}[{i}].') for i, v in enumerate(data)]
    if prefix[:-1] not in keys and not (prefix[:-1].endswith(']') and
                                        prefix[:-1].rsplit('[', 1)[0] + '[0]' in keys):
        return data
    if isinstance(data, bool):
        return level >= 0.5
    if isinstance(data, float):
        return float(level)
    if isinstance(data, int):
        return round(level)
    return data


def _at_level(template: dict[str, object], keys: set[str], level: float) -> dict[str, object]:
    """The template message (a message dict) with its varying numeric fields at `level`."""
    return {k: (v if k in _SKIP else _set_level(v, keys, level, f'{k}.'))
            for k, v in template.items()}


def command_fields(data: object, prefix: str = '') -> Iterator[tuple[str, Value | int]]:
    """Every leaf of a command's message dict, stamps left out, as it is: numbers,
    booleans and texts ('data', 'linear.x', 'lights[2].on', 'state')."""
    if isinstance(data, dict):
        for key, value in data.items():
            if key not in _SKIP:
                yield from command_fields(value, f'{prefix}{key}.')
    elif isinstance(data, list | tuple):
        for i, value in enumerate(data[:_ITEMS]):
            yield from command_fields(value, f'{prefix[:-1]}[{i}].')
    elif isinstance(data, bool | str):
        yield prefix[:-1], data[:80] if isinstance(data, str) else data
    elif isinstance(data, int | float) and math.isfinite(float(data)):
        yield prefix[:-1], data


def _fields(data: object) -> Iterator[tuple[str, Value]]:
    """The command's leaves, numbers as floats (an Int32's 3 and a Float64's 3.0 alike)."""
    for key, value in command_fields(data):
        yield key, value if isinstance(value, bool | str | float) else float(value)


def _summary(samples: list[Sample]) -> Sample:
    """Per field: the median of a number, the most frequent of a text."""
    keys = {k for s in samples for k in s}
    summary: Sample = {}
    for key in sorted(keys):
        values = [s[key] for s in samples if key in s]
        numbers = [v for v in values if isinstance(v, float)]
        if len(numbers) == len(values):
            summary[key] = statistics.median(numbers)
        else:  # a bool or a word: the most frequent (a field keeps its type)
            summary[key] = statistics.mode(values)
    return summary


def _moved(a: Value, b: Value) -> float:
    """How far a field moved between two summaries, in units of its noise floor (a word
    or a bool that changed moved by 2; numbers: the change over a scale of 1e-3 of their
    size)."""
    if not (isinstance(a, float) and isinstance(b, float)):
        return 2.0 if a != b else 0.0
    return abs(b - a) / (1e-6 + 1e-3 * max(abs(a), abs(b)))


def _differs(before: Sample, sample: Sample) -> bool:
    return any(_moved(before[k], sample[k]) > 1.0 for k in before.keys() & sample.keys())


def _answered(samples: list[Sample], before: Sample | None) -> int | None:
    """Where the commands that answer a level start (None: not yet): the first run of
    `_SAMPLES` equal commands that differs from the previous level's. The grader's input
    is constant, so a controller's answer to it is too; what it still sends from older
    input (a varying sensor, a queue) is not, and a constant controller never differs."""
    for i in range(len(samples) - _SAMPLES + 1):
        run = samples[i:i + _SAMPLES]
        if (not any(_differs(run[0], s) for s in run[1:])
                and (before is None or _differs(before, run[0]))):
            return i
    return None


def _follows(low1: Sample, high: Sample, low2: Sample) -> bool:
    for key in low1.keys() & high.keys() & low2.keys():
        a, b, c = low1[key], high[key], low2[key]
        if not (isinstance(a, float) and isinstance(b, float) and isinstance(c, float)):
            if a != b and c != b:  # a bool or a word: it flips with the input and back
                return True
            continue
        up, down = b - a, c - b
        scale = 1e-6 + 1e-3 * max(abs(a), abs(b))
        if abs(up) > scale and abs(down) > scale and up * down < 0:
            return True
    return False


class _Wires:
    """The grader's publisher on the sensor topic and subscription to the commands: its
    own for the kit's types, through the helper process (`Bridge`) for a student's own."""

    def __init__(self, sess: Session, bridge: Bridge | None, sensor: TopicSeen,
                 command: TopicSeen, on_command: Callable[[dict[str, Any]], None]) -> None:
        from rclpy.qos import QoSProfile, QoSReliabilityPolicy

        from robot_lab.messages import message_class, message_from_yaml, message_to_dict

        self.sess, self.bridge, self.sensor, self.command = sess, bridge, sensor, command
        self.publisher: Any = None
        self.subscription: Any = None
        try:
            in_cls = message_class(sensor.types[0])
        except Exception:
            in_cls = None
        try:
            out_cls = message_class(command.types[0])
        except Exception:
            out_cls = None
        if bridge is None and (in_cls is None or out_cls is None):
            raise LookupError('not a type the grader loads')
        self.make: Callable[[dict[str, Any]], Any] = (
            (lambda data: message_from_yaml(in_cls, data)) if in_cls else (lambda data: data))
        if in_cls is not None:
            self.publisher = sess.node.create_publisher(in_cls, sensor.name, 10)
        else:
            assert bridge is not None
            bridge.advertise(sensor.name, sensor.types[0])
        if out_cls is not None:
            def on_message(msg: Any) -> None:
                with contextlib.suppress(Exception):
                    on_command(message_to_dict(msg))

            self.subscription = sess.node.create_subscription(
                out_cls, command.name, on_message,
                QoSProfile(depth=100, reliability=QoSReliabilityPolicy.BEST_EFFORT))
        else:
            assert bridge is not None
            bridge.subscribe(command.name, command.types[0], on_command)

    def publish(self, message: Any) -> None:
        if self.publisher is not None:
            self.publisher.publish(message)
        else:
            assert self.bridge is not None
            self.bridge.publish(self.sensor.name, message)

    def matched(self) -> int:
        if self.publisher is not None:
            return int(self.publisher.get_subscription_count())
        assert self.bridge is not None
        return self.bridge.matched.get(self.sensor.name, 0)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            if self.publisher is not None:
                self.sess.node.destroy_publisher(self.publisher)
            if self.subscription is not None:
                self.sess.node.destroy_subscription(self.subscription)
        if self.bridge is not None:
            self.bridge.unsubscribe(self.command.name)


def _alive(sess: Session, node: str | None) -> bool:
    """Whether `node` is still in the graph (a controller that died is not the grader's)."""
    from robot_lab.graph.discovery import full_node_names

    try:
        return node in full_node_names(sess, include_hidden=False)
    except Exception:
        return True


def drive_controller(sess: Session, obs: Observation, roles: Roles,
                     pause: Callable[[], tuple[Callable[[], None], str] | None],
                     bridge: Bridge | None = None) -> Response:
    """Drive the sensor topic low → high → low and read the commands (see the module doc).

    `pause()` takes the student's sensor out of the loop and returns how to undo it and
    what it did (None: it cannot be done here, the controller is not tested). `bridge`
    carries the messages of types the grader does not load (a student's own interfaces).
    """
    sensor = obs.topics.get(roles.sensor_topic or '')
    command = obs.topics.get(roles.command_topic or '')
    if (sensor is None or command is None or not sensor.values or len(sensor.types) != 1
            or len(command.types) != 1):
        return Response(False, why='no sensor readings of a single type to imitate')
    keys, low, high = _varying(list(sensor.values))
    template = sensor.values[-1]
    lock = threading.Lock()
    received: list[Sample] = []  # the commands, in the order they came

    def on_command(data: dict[str, Any]) -> None:
        sample: Sample = dict(_fields(data))
        with lock:
            received.append(sample)

    try:
        wires = _Wires(sess, bridge, sensor, command, on_command)
    except LookupError as err:
        return Response(False, why=str(err))
    paused = pause()
    if paused is None:
        wires.close()
        return Response(False, why='the sensor could not be taken out of the loop')
    resume, how = paused
    response = Response(True, how=f'{how}; the grader published on `{sensor.name}` instead')
    try:
        messages = {lvl: wires.make(_at_level(template, keys, lvl)) for lvl in (low, high)}

        # Wait for the match (no command before it can answer the grader), then take the
        # commands the controller sends on its own (a timer on its last reading) as the
        # level before the first.
        end = time.monotonic() + _MATCH
        while time.monotonic() < end and not wires.matched():
            time.sleep(0.05)
        if not wires.matched() and _alive(sess, roles.controller):
            response.fault = (f"the controller's subscription to `{sensor.name}` did not match "
                              f"the grader's publisher within {_MATCH:g} s")
            return response
        with lock:
            before: Sample | None = _summary(received[-_SAMPLES:]) if received else None

        def hold(level: float) -> list[Sample]:
            """Publish `level` until the controller has answered it (see `_answered`), at
            most `_PATIENCE` s; the commands that answered, else the last ones sent."""
            with lock:
                first = len(received)
            end = time.monotonic() + _PATIENCE
            while True:
                wires.publish(messages[level])
                time.sleep(1.0 / _RATE)
                with lock:
                    new = received[first:]
                start = _answered(new, before)
                if start is not None:
                    return new[start:start + _SAMPLES]
                if time.monotonic() >= end:
                    return new[-_SAMPLES:]

        def drive(levels: tuple[float, float]) -> bool:
            nonlocal before
            summaries = []
            for level in (levels[0], levels[1], levels[0]):
                window = hold(level)
                # No new command: the last one stands (a lamp told only when it switches).
                summaries.append(_summary(window) if window else dict(before or {}))
                before = summaries[-1] or before
                response.levels.append((level, summaries[-1], len(window)))
            return _follows(*summaries)

        response.follows = drive((low, high))
        if not response.follows:
            # The readings seen may all lie where an honest controller saturates (a short
            # window of a slow sensor profile): drive a wider range once before judging.
            wide = _wider(low, high)
            messages.update({lvl: wires.make(_at_level(template, keys, lvl)) for lvl in wide})
            response.follows = drive(wide)
    finally:
        wires.close()
        resume()
    return response
