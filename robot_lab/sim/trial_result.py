"""What a trial measured (`robot_lab.sim.trial`), and the words a student reads about it.

Pure Python over the referee's ground-truth samples, so the judgement is tested without a
simulator: `TrialResult.from_samples` turns the samples into the figures (gaps, speeds,
rest, contact), `describe()` says what happened in one line, and `judge_stop` grades a
"stop before the obstacle" behaviour, naming the first mistake a student can act on (no
bridge, no command, a collision, still moving, the wrong distance, wall-clock time).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ['EndWatch', 'Speedometer', 'TrialResult', 'TrialSample', 'bridge_command',
           'judge_stop']

_MOVED = 0.02  # metres from the start: the robot was driven, not just settling
_SPEED_WINDOW = 0.05  # sim seconds over which a sample's speed is measured
_TYPES = {'scan': ('sensor_msgs/msg/LaserScan', 'gz.msgs.LaserScan', '['),
          'cmd_vel': ('geometry_msgs/msg/Twist', 'gz.msgs.Twist', ']')}


@dataclass(frozen=True)
class TrialSample:
    """The ground truth at one sim time (seconds from the run's start)."""

    t: float
    gap: float  # metres between the robot's and the obstacle's collision geometry
    speed: float  # m/s of the root link over the plane
    contact: bool
    x: float
    y: float
    yaw: float


def bridge_command(gz_topic: str, kind: str) -> str:
    """The parameter_bridge call that makes gz topic `gz_topic` the ROS topic."""
    ros, gz, way = _TYPES[kind]
    name = gz_topic if gz_topic.startswith('/') else '/' + gz_topic
    return f'ros2 run ros_gz_bridge parameter_bridge {name}@{ros}{way}{gz}'


class Speedometer:
    """The referee's samples, one at a time, as TrialSamples: each one's speed is over the
    samples of the last 50 ms of sim time (the one before it if none)."""

    def __init__(self, t0: float = 0.0) -> None:
        self.t0 = t0
        self.recent: deque[tuple[float, float, float]] = deque()  # t, x, y

    def sample(self, item: Mapping[str, Any]) -> TrialSample:
        t, x, y = float(item['t']), float(item['x']), float(item['y'])
        while len(self.recent) > 1 and t - self.recent[0][0] > _SPEED_WINDOW:
            self.recent.popleft()  # keeping the one before, should all be older
        earlier = self.recent[0] if self.recent else (t, x, y)
        dt = t - earlier[0]
        speed = math.hypot(x - earlier[1], y - earlier[2]) / dt if dt > 0 else 0.0
        self.recent.append((t, x, y))
        return TrialSample(t - self.t0, float(item['gap']), speed, bool(item['contact']), x, y,
                           float(item['yaw']))


class EndWatch:
    """Which end a run met first, fed its samples in order: at rest for `until_rest` sim s
    after it moved, or `after_collision` sim s after a contact. A run cut at that sample
    ends there however late its watcher noticed, so one trajectory gives one result."""

    def __init__(self, until_rest: float, after_collision: float, stop_speed: float) -> None:
        self.until_rest, self.after_collision = until_rest, after_collision
        self.stop_speed = stop_speed
        self.start: TrialSample | None = None
        self.moved = False
        self.still_since: float | None = None
        self.hit: float | None = None

    def feed(self, sample: TrialSample) -> str | None:
        """'rest', 'collision', or None while the run goes on."""
        start = self.start = self.start or sample
        self.moved = self.moved or math.hypot(sample.x - start.x,
                                              sample.y - start.y) > _MOVED
        if sample.speed >= self.stop_speed:
            self.still_since = None
        elif self.still_since is None:
            self.still_since = sample.t
        if (self.until_rest and self.moved and self.still_since is not None
                and sample.t - self.still_since >= self.until_rest):
            return 'rest'
        if self.hit is None and sample.contact:
            self.hit = sample.t
        if self.hit is not None and sample.t - self.hit >= self.after_collision:
            return 'collision'
        return None


@dataclass(frozen=True)
class TrialResult:
    """A run's figures, from the simulator's ground truth and the ROS graph."""

    samples: tuple[TrialSample, ...]
    sim_seconds: float
    start_distance: float
    final_distance: float
    min_distance: float
    max_speed: float
    moved: bool  # the robot left its start by more than 2 cm
    rest_seconds: float  # sim seconds at rest at the end (speed below stop_speed)
    stopped: bool  # at rest for at least `until_rest` at the end
    stopped_at: float | None  # when that final rest began
    collision: bool
    collision_time: float | None
    collision_speed: float | None  # m/s just before the first contact
    commands: int  # commands the simulator's robot took during the run
    ended: str = 'sim_time'  # sim_time | rest | collision | wall_time
    wall_seconds: float = 0.0
    bridged: bool = True  # the trial ran the bridge (False: the caller's job)
    scan_publishers: tuple[str, ...] = ()
    scan_subscribers: tuple[str, ...] = ()
    cmd_vel_publishers: tuple[str, ...] = ()
    use_sim_time: Mapping[str, bool | None] = field(default_factory=dict)
    scan_topics: tuple[str, ...] = ('/scan',)  # the gz topics the robot's lidars publish
    cmd_topics: tuple[str, ...] = ('/cmd_vel',)  # the gz topics its DiffDrive takes

    @property
    def received_cmd_vel(self) -> bool:
        """Whether any command reached the simulated robot."""
        return self.commands > 0

    @property
    def sim_time_ok(self) -> bool | None:
        """False if a /cmd_vel publisher runs without use_sim_time; None if unknown."""
        values = list(self.use_sim_time.values())
        if any(v is False for v in values):
            return False
        return True if values and all(values) else None

    @classmethod
    def from_samples(cls, raw: Sequence[Mapping[str, Any]], t0: float = 0.0,
                     stop_speed: float = 0.02, until_rest: float = 0.5,
                     commands_before: int = 0, **extra: Any) -> TrialResult:
        """The figures of the referee's `@truth` samples taken since sim time `t0`."""
        meter = Speedometer(t0)
        samples = [meter.sample(item) for item in raw]
        if not samples:
            return cls((), 0.0, math.nan, math.nan, math.nan, 0.0, False, 0.0, False, None,
                       False, None, None, 0, **extra)
        first, last = samples[0], samples[-1]
        moved = any(math.hypot(s.x - first.x, s.y - first.y) > _MOVED for s in samples)
        rest_from = last.t
        for sample in reversed(samples):
            if sample.speed >= stop_speed:
                break
            rest_from = sample.t
        rest = last.t - rest_from
        hit = next((i for i, s in enumerate(samples) if s.contact), None)
        hit_speed = None
        if hit is not None:
            before = [s.speed for s in samples[max(0, hit - 5):hit + 1]]
            hit_speed = max(before)
        return cls(tuple(samples), last.t, first.gap, last.gap, min(s.gap for s in samples),
                   max(s.speed for s in samples), moved, rest, rest >= until_rest,
                   rest_from if rest >= until_rest else None, hit is not None,
                   samples[hit].t if hit is not None else None, hit_speed,
                   int(raw[-1].get('commands', 0)) - commands_before, **extra)

    # -- words -----------------------------------------------------------------------
    def wiring_problem(self) -> str | None:
        """Why the controller could not drive the robot, if it could not: no /scan, no
        subscriber to it, no /cmd_vel, or commands that never reached the simulator."""
        scan = '/' + (self.scan_topics[0] if self.scan_topics else 'scan').lstrip('/')
        cmd = '/' + (self.cmd_topics[0] if self.cmd_topics else 'cmd_vel').lstrip('/')
        if not self.scan_publishers:
            return (f'never received /scan: nothing publishes /scan; the simulator publishes '
                    f'gz topic {scan}; bridge it with: {bridge_command(scan, "scan")}')
        if not self.cmd_vel_publishers:
            return 'nothing publishes /cmd_vel: the robot was never commanded'
        if not self.received_cmd_vel:
            if not self.bridged:
                return (f'/cmd_vel never reached the simulator: it takes gz topic {cmd}; '
                        f'bridge it with: {bridge_command(cmd, "cmd_vel")}')
            return ('no /cmd_vel message reached the simulator (its publisher published '
                    'nothing during the run)' + ('' if self.scan_subscribers else
                                                 '; no node subscribes to /scan'))
        return None

    def sim_time_problem(self) -> str | None:
        """The nodes publishing /cmd_vel that run on the wall clock, if any."""
        wrong = [name for name, value in self.use_sim_time.items() if value is False]
        if not wrong:
            return None
        return (f'{", ".join(wrong)} runs without use_sim_time: its clock is the wall '
                f"clock, not the simulation's /clock; set the parameter use_sim_time:=true")

    def describe(self, obstacle: str = 'the obstacle') -> str:
        """One line of what happened, for feedback."""
        if not self.samples:
            return 'the simulation ran no time (it ended before the first sample)'
        wiring = self.wiring_problem()
        if wiring is not None:
            text = wiring
        elif self.collision and self.collision_time is not None:
            text = (f'hit {obstacle} at {self.collision_speed or 0.0:.2f} m/s at '
                    f't={self.collision_time:.1f} s (sim time)')
        elif self.stopped and self.stopped_at is not None:
            text = (f'stopped {self.final_distance:.2f} m from {obstacle} at '
                    f't={self.stopped_at:.1f} s (sim time)')
        else:
            speed = self.samples[-1].speed
            text = (f'still moving at {speed:.2f} m/s after {self.sim_seconds:.1f} s of sim '
                    f'time, {self.final_distance:.2f} m from {obstacle}')
        if self.ended == 'wall_time':
            text += (f' (the trial reached its wall-clock limit after {self.wall_seconds:.0f} s '
                     f'at sim time {self.sim_seconds:.1f} s)')
        sim_time = self.sim_time_problem()
        return text + (f'; {sim_time}' if sim_time else '')


def judge_stop(result: TrialResult, target: float, tolerance: float, *,
               obstacle: str = 'the obstacle', require_sim_time: bool = True
               ) -> tuple[bool, str]:
    """(passed, one line) for "drive forward and stop `target` ± `tolerance` m before the
    obstacle, without touching it", the distance measured from the robot's collision
    geometry by the simulator."""
    aim = f'(target {target:.2f} ± {tolerance:.2f})'
    line = result.describe(obstacle)
    if result.wiring_problem() is not None or result.collision or not result.samples:
        return False, line
    if not result.stopped:
        return False, f'{line} {aim}'
    if abs(result.final_distance - target) > tolerance:
        side = 'too close' if result.final_distance < target else 'too far'
        return False, f'{line} {aim}: {side}'
    if require_sim_time and result.sim_time_ok is False:
        return False, line
    return True, f'{line} {aim}'
