"""The simulator of a trial (`robot_lab.sim.trial`), with its ground truth on stdout.

It is `gz sim` (the kit's `server.Server` on the partition's socket, so the bridge, `gz
topic` and `create` reach it as usual) with a robot already spawned, started paused, and
one more duty: every `--sample` sim seconds it prints what MuJoCo knows and no topic
tells, as a line `@truth {json}`: the sim time, the signed gap between the robot's
collision geometry and the obstacle's (`mj_geomDistance`, negative when they overlap),
whether any of their geoms touch, the root link's pose, and how many commands the robot's
systems took. The trial reads these lines; odometry never enters the judgement.

Run by the trial only: `python -m robot_lab.sim.referee SPEC.json`. It prints `@ready
{json}` once the robot stands in the world (paused), or `@error {"phase": "world" |
"robot", "message"}` when one was refused, and steps once a client sends
`control pause: false`, until `iterations` steps have run. With `lockstep` it waits, after
each scan, for the controller's command (see `RefereeSimulation`).
"""

from __future__ import annotations

import json
import queue
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed
import numpy

from robot_lab.errors import RobotLabError
from robot_lab.sim.robot import SpawnedRobot
from robot_lab.sim.server import Server, _listen
from robot_lab.sim.simulation import Simulation
from robot_lab.sim.systems import DiffDrive, Lidar, Publish
from robot_lab.sim.transport import Connection, partition, socket_path, topic_name

__all__ = ['main']

_FAR = 100.0  # metres: beyond this the gap is reported as this
_MISSES = 3  # scans in a row without a command before lockstep runs on


def _geoms_of(model: Any, prefixes: Sequence[str]) -> list[int]:
    """The geoms whose body's name starts with one of `prefixes` (`model::`)."""
    found = []
    for geom in range(model.ngeom):
        body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[geom]))
        if body and any(str(body).startswith(p) for p in prefixes):
            found.append(geom)
    return found


class Truth:
    """What the referee measures after a step; `sample()` is one `@truth` line's dict."""

    def __init__(self, sim: RefereeSimulation, robot: str, obstacles: Sequence[str]) -> None:
        self.sim = sim
        self.robot = robot
        model = sim.model
        self.robot_geoms = _geoms_of(model, [f'{robot}::'])
        if obstacles:
            self.obstacle_geoms = _geoms_of(model, [f'{o}::' for o in obstacles])
        else:  # every geom of the world but the ground's and the robot's
            mine = set(self.robot_geoms)
            self.obstacle_geoms = [g for g in range(model.ngeom) if g not in mine
                                   and model.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE]
        self.pairs = {frozenset((a, b)) for a in self.robot_geoms for b in self.obstacle_geoms}

    def gap(self) -> float:
        fromto = numpy.zeros(6)
        best = _FAR
        for a in self.robot_geoms:
            for b in self.obstacle_geoms:
                best = min(best, float(mujoco.mj_geomDistance(
                    self.sim.model, self.sim.data, a, b, _FAR, fromto)))
        return best

    def contact(self) -> bool:
        data = self.sim.data
        return any(frozenset((int(data.contact.geom1[i]), int(data.contact.geom2[i])))
                   in self.pairs for i in range(data.ncon))

    def sample(self) -> dict[str, Any]:
        gap = self.gap()
        touching = self.contact() or gap < 0.0
        x, y, yaw = self.sim.body_pose(self.robot)
        return {'t': self.sim.time_ns / 1e9, 'gap': gap, 'contact': touching, 'x': x, 'y': y,
                'yaw': yaw, 'commands': self.sim.commands}


def _ground_gap(sim: RefereeSimulation, robot: str) -> float:
    """The signed gap between the robot's geoms and the ground plane(s)."""
    truth = Truth(sim, robot, [])
    truth.obstacle_geoms = [g for g in range(sim.model.ngeom)
                            if sim.model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE]
    return truth.gap() if truth.obstacle_geoms and truth.robot_geoms else 0.0


class RefereeSimulation(Simulation):
    """The world, counting the commands its systems take and printing `@truth` samples
    every `every` steps (`Server.run` steps one at a time).

    In lockstep (`server` set), each step that published a scan waits until a command
    comes back (≤ `patience` wall seconds), so a controller that answers each scan drives
    the same trajectory whatever the host's load; after `_MISSES` scans in a row without
    an answer (no controller yet, or none that answers scans) it runs on, until one comes.
    """

    truth: Truth | None = None
    every = 10
    commands = 0
    server: Server | None = None  # set: lockstep
    relay: Publish = staticmethod(lambda topic, kind, message: None)
    patience = 0.5
    scan_topics: frozenset[str] = frozenset()
    cmd_topics: frozenset[str] = frozenset()
    scanned = False
    misses = 0

    def command(self, topic: str, message: dict[str, Any]) -> bool:
        taken = super().command(topic, message)
        self.commands += int(taken)
        if taken and topic_name(topic) in self.cmd_topics:
            self.misses = 0
        return taken

    def step(self, count: int = 1) -> None:
        for _ in range(count):
            self.scanned = False
            super().step()
            if self.truth is not None and self.steps % self.every == 0:
                _emit('truth', self.truth.sample())
            if self.scanned and self.server is not None and self.misses < _MISSES:
                self._await_command(self.server)

    def published(self, topic: str, kind: str, message: dict[str, Any]) -> None:
        """What the systems publish goes to the server's clients; a scan is noted."""
        if topic in self.scan_topics:
            self.scanned = True
        self.relay(topic, kind, message)

    def _await_command(self, server: Server) -> None:
        """Serve the clients' frames until a command for the robot arrives."""
        deadline = time.monotonic() + self.patience
        while (left := deadline - time.monotonic()) > 0:
            try:
                connection, frame = server.inbox.get(timeout=left)
            except queue.Empty:
                break
            server.handle(connection, frame)
            if server.paused:  # the trial ended the run
                return
            if frame.get('op') == 'pub' and topic_name(str(frame.get('topic'))) in \
                    self.cmd_topics:
                return
        self.misses += 1


class RefereeServer(Server):
    """The kit's server, marking each pause and resume with the commands taken so far (a
    run counts the commands since its start, not a previous run's late answers), and
    saying how many clients subscribe to each topic (`{"op": "subscribers"}`: is a bridge
    connected yet?)."""

    sim: RefereeSimulation

    def handle(self, connection: Connection, frame: dict[str, Any]) -> None:
        if frame.get('op') != 'subscribers':
            super().handle(connection, frame)
            return
        with self.lock:
            counts = {topic: len(clients) for topic, clients in self.subscribers.items()}
        connection.send({'op': 'reply', 'id': frame.get('id'), 'ok': True, 'data': counts})

    def control(self, request: dict[str, Any]) -> None:
        super().control(request)
        if 'pause' in request:
            _emit('mark', {'paused': self.paused, 'commands': self.sim.commands,
                           't': self.sim.time_ns / 1e9})


class SpawnError(RobotLabError):
    """The simulator refused the robot (its URDF), not the world: the `robot` phase."""


def _spawned(spec: dict[str, Any]) -> tuple[RefereeSimulation, SpawnedRobot]:
    """The world with the robot spawned; at `z` None it rests on the ground (1 mm above,
    found by spawning it at z 0 and measuring), as a lab's `create -z` would place it."""
    x, y, z = spec['xyz']

    def spawn(sim: RefereeSimulation, at: tuple[float, float, float]) -> SpawnedRobot:
        try:
            return sim.spawn(spec['urdf'], spec['name'], at, tuple(spec['rpy']),
                             spec.get('source', 'robot_description'))
        except RobotLabError as error:
            raise SpawnError(str(error)) from error

    if z is None:
        probe = RefereeSimulation(spec['world'], seed=0, warn=lambda line: None)
        spawn(probe, (x, y, 0.0))
        z = 0.001 - _ground_gap(probe, spec['name'])
    sim = RefereeSimulation(spec['world'], seed=int(spec.get('seed', 0)))
    return sim, spawn(sim, (x, y, z))


def _emit(tag: str, payload: dict[str, Any]) -> None:
    print(f'@{tag} {json.dumps(payload)}', flush=True)


def _run(spec: dict[str, Any]) -> int:
    path = socket_path()
    listener = _listen(path)
    try:
        sim, robot = _spawned(spec)
        sim.truth = truth = Truth(sim, robot.name, spec.get('obstacles') or [])
        sim.every = max(1, round(float(spec.get('sample', 0.01)) / sim.info.step))
        server = RefereeServer(sim, listener)
        server.paused = True
        sim.scan_topics = frozenset(s.topic for s in sim.systems if isinstance(s, Lidar))
        sim.cmd_topics = frozenset(s.cmd_topic for s in sim.systems if isinstance(s, DiffDrive))
        sim.relay, sim.on_publish = server.publish, sim.published
        if spec.get('lockstep'):
            sim.server = server
        _emit('ready', {
            'partition': partition(), 'socket': str(path), 'step': sim.info.step,
            'world': sim.info.name, 'robot_geoms': len(truth.robot_geoms),
            'obstacle_geoms': len(truth.obstacle_geoms),
            'scan_topics': sorted(sim.scan_topics), 'cmd_topics': sorted(sim.cmd_topics),
            'first': truth.sample()})
        rate = float(spec.get('speed') or sim.info.real_time_factor) / sim.info.step
        server.run(rate, int(spec['iterations']))
        _emit('done', truth.sample())
    finally:
        listener.close()
        path.unlink(missing_ok=True)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    try:
        spec = json.loads(Path(args[0]).read_text())
        return _run(spec)
    except RobotLabError as error:
        phase = 'robot' if isinstance(error, SpawnError) else 'world'
        _emit('error', {'phase': phase, 'message': str(error)})
        return 1
    except KeyboardInterrupt:
        return 0


if __name__ == '__main__':
    sys.exit(main())
