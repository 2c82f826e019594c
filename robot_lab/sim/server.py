"""The simulator process: `gz sim [-r] [-s] [-v N] world.sdf`, as robot_lab runs it.

It loads the world, serves the partition's socket (`transport`), spawns what `create`
asks for, and steps the physics at the world's real-time factor, publishing what the
systems publish to whoever subscribed. It says what it is before anything else: its first
line names robot_lab and the engine, never Gazebo. Without `-r` it starts paused, as Gazebo
does (whose GUI has a play button): /clock holds at 0 until a WorldControl `pause: false`
comes, and its log says how to send one.

Pacing holds the world's real-time factor on average: steps are due at absolute deadlines
counted from an anchor (set when it starts running, after a pause, a reset or steps on
request), so a late wake-up is caught up, never carried forward as drift. The statistics
(/world/<name>/stats, 10 a wall second as Gazebo throttles them) count real time as
Gazebo's realTimeWatch does: running time only, paused time left out.
"""

from __future__ import annotations

import argparse
import queue
import shlex
import signal
import socket
import struct
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import RobotLabError
from robot_lab.sim.about import identity
from robot_lab.sim.transport import Connection, connect, partition, socket_path

if TYPE_CHECKING:
    from robot_lab.sim.simulation import Simulation

__all__ = ['gzserver_main', 'identity', 'main', 'split_gz_args', 'start_command']  # identity: about

Frame = dict[str, Any]
STATS_PERIOD = 0.1  # wall seconds between /world/<name>/stats messages (Gazebo: 10 a second)
SEND_TIMEOUT = 2.0  # wall seconds a client may leave the simulator's messages unread


def start_command(world: str) -> str:
    """The `gz service` line that starts a paused world, as Gazebo's docs write it."""
    return (f'gz service -s /world/{world}/control --reqtype gz.msgs.WorldControl '
            f"--reptype gz.msgs.Boolean --timeout 3000 --req 'pause: false'")


def split_gz_args(argv: Sequence[str]) -> list[str]:
    """`gz_args:="-r room.sdf"` arrives as one argument (or none): split as a shell would."""
    out: list[str] = []
    for arg in argv:
        if arg == '--ros-args':  # a launch file's Node adds its own: not gz sim's
            break
        out += shlex.split(arg)
    return out


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='gz sim', description="robot_lab's simulator, with gz sim's arguments.")
    parser.add_argument('world', nargs='?', default='empty.sdf')
    parser.add_argument('-r', dest='run', action='store_true', help='run on start')
    parser.add_argument('-s', dest='server', action='store_true', help='server only (always)')
    parser.add_argument('-g', dest='gui', action='store_true', help='GUI only: not available')
    parser.add_argument('-v', '--verbose', type=int, nargs='?', const=1, default=1)
    parser.add_argument('--iterations', type=int, default=0, help='stop after N steps')
    parser.add_argument('-z', dest='rate', type=float, default=0.0,
                        help="steps per wall-clock second (0: the world's real-time factor)")
    parser.add_argument('--seed', type=int, default=0, help='the random seed (sensor noise)')
    parser.add_argument('--version', action='store_true')
    parser.add_argument('--headless-rendering', action='store_true', help='no renderer: ignored')
    for option in _ENGINE_OPTIONS:
        parser.add_argument(option, default='', help='not available: ignored, with a line')
    return parser


_ENGINE_OPTIONS = ('--render-engine', '--render-engine-gui', '--render-engine-server',
                   '--physics-engine')


def _ignored_options(args: argparse.Namespace) -> list[str]:
    """One line for each gz sim option given that the kit has nothing for."""
    lines = [f"[Wrn] gz sim {option} {getattr(args, option[2:].replace('-', '_'))}: "
             f"robot_lab's simulator {'runs MuJoCo' if 'physics' in option else 'has no renderer'}"
             f'; ignored' for option in _ENGINE_OPTIONS
             if getattr(args, option[2:].replace('-', '_'))]
    if args.headless_rendering:
        lines.append("[Wrn] gz sim --headless-rendering: robot_lab's simulator has no "
                     'renderer (its lidar casts rays in MuJoCo); ignored')
    return lines


class Server:
    """The simulation, its socket, and its clients' subscriptions."""

    def __init__(self, sim: Simulation, listener: socket.socket, paused: bool = False) -> None:
        self.sim = sim
        self.listener = listener
        self.inbox: queue.Queue[tuple[Connection, Frame]] = queue.Queue()
        self.subscribers: dict[str, set[Connection]] = {}
        self.types: dict[str, str] = {}
        self.lock = threading.Lock()
        self.paused = paused
        self.rate = 1000.0  # steps per wall second; run() sets it
        self.anchor = (time.monotonic(), 0)
        self.run_time = 0.0  # wall seconds spent running, up to run_since
        self.run_since = time.monotonic()
        self.last_stats = (time.monotonic(), 0, 0.0)  # wall, sim ns, running s
        self.run_to: int | None = None  # sim ns at which to pause (WorldControl's target)
        sim.on_publish = self.publish
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                sock, _ = self.listener.accept()
            except OSError:
                return
            # a client that stops reading (a hung bridge) must not stop the world: a send
            # that cannot go within SEND_TIMEOUT fails, and the client is dropped
            seconds = int(SEND_TIMEOUT)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDTIMEO, struct.pack(
                'll', seconds, int((SEND_TIMEOUT - seconds) * 1e6)))
            connection = Connection(sock)
            threading.Thread(target=self._read, args=(connection,), daemon=True).start()

    def _read(self, connection: Connection) -> None:
        while (frame := connection.receive()) is not None:
            if frame.get('op') == 'sub':  # subscriptions take effect at once
                with self.lock:
                    self.subscribers.setdefault(str(frame['topic']), set()).add(connection)
            else:
                self.inbox.put((connection, frame))
        with self.lock:
            for clients in self.subscribers.values():
                clients.discard(connection)

    def publish(self, topic: str, kind: str, message: dict[str, Any]) -> None:
        self.types[topic] = kind
        with self.lock:
            clients = list(self.subscribers.get(topic, ()))
        frame = {'op': 'msg', 'topic': topic, 'type': kind, 'msg': message}
        for client in clients:
            if not client.send(frame):
                self._drop(client)

    def _drop(self, client: Connection) -> None:
        """Forget a client that has gone or stopped reading (gz-transport drops messages
        for a slow subscriber; the kit's framed stream cannot skip one, so it closes)."""
        with self.lock:
            for clients in self.subscribers.values():
                clients.discard(client)
        client.close()

    def handle(self, connection: Connection, frame: Frame) -> None:
        op = frame.get('op')
        if op == 'pub':
            self.types.setdefault(str(frame['topic']), str(frame.get('type', '')))
            self.sim.command(str(frame['topic']), frame.get('msg') or {})
        elif op == 'create':
            reply: Frame = {'op': 'reply', 'id': frame.get('id'), 'ok': True}
            try:
                self.create(frame)
            except RobotLabError as error:
                reply.update(ok=False, error=str(error))
                print(f'[Err] {error}', flush=True)
            connection.send(reply)
        elif op == 'control':
            world = frame.get('world') or self.sim.info.name
            if world != self.sim.info.name:  # Gazebo: no such service, the call times out
                connection.send({'op': 'reply', 'id': frame.get('id'), 'ok': False,
                                 'error': f'no world {world!r} here: the simulation runs '
                                          f'{self.sim.info.name!r} (/world/'
                                          f'{self.sim.info.name}/control)'})
                return
            self.control(frame)
            connection.send({'op': 'reply', 'id': frame.get('id'), 'ok': True,
                             'data': {'paused': self.paused, 'iterations': self.sim.steps}})
        elif op == 'topics':
            advertised = {t: k for system in self.sim.systems for t, k in
                          system.advertised().items()}
            topics = {**advertised, **self.types,
                      **{t: self.types.get(t, '') for t in self.sim.subscriptions}}
            connection.send({'op': 'reply', 'id': frame.get('id'), 'ok': True, 'data': topics})

    def create(self, frame: Frame) -> None:
        """`/world/<name>/create`: a URDF robot (with its systems) or an SDF model."""
        from robot_lab.sim.xml_tree import parse

        world = str(frame.get('world') or self.sim.info.name)
        if world != self.sim.info.name:
            raise RobotLabError(f'no world {world!r} here: the simulation runs '
                                f'{self.sim.info.name!r}', fix=f'drop -world, or give -world '
                                                               f'{self.sim.info.name}')
        text, source = str(frame['urdf']), str(frame.get('source', 'robot_description'))
        xyz, rpy = tuple(frame.get('xyz', (0, 0, 0))), tuple(frame.get('rpy', (0, 0, 0)))
        root = parse(text, source)
        if root.tag == 'robot':  # unnamed: the URDF's robot name, as gz-sim names the model
            name = str(frame.get('name') or root.attrib.get('name') or 'robot')
            robot = self.sim.spawn(text, name, xyz, rpy, source)
            print(f'[Msg] Spawned {robot.name!r} ({len(robot.bodies)} links) at {list(xyz)}',
                  flush=True)
        else:
            name = self.sim.spawn_model(text, str(frame.get('name') or ''), xyz, rpy, source)
            print(f'[Msg] Spawned SDF model {name!r} at {list(xyz)}', flush=True)

    def control(self, request: Frame) -> None:
        """gz.msgs.WorldControl, as `/world/<name>/control` takes it: pause, (multi_)step,
        reset; steps asked for while paused run at once."""
        now = time.monotonic()
        if 'pause' in request and bool(request['pause']) != self.paused:
            self.run_time = self.running_time(now)
            self.run_since = now
            self.paused = bool(request['pause'])
            print(f'[Msg] World {"paused" if self.paused else "running"}', flush=True)
            self._anchor()
        if request.get('reset'):
            self.sim.reset()
            self.run_time, self.run_since = 0.0, now  # Gazebo's rewind: real time 0 too
            self.last_stats = (now, 0, 0.0)
            print('[Msg] World reset: time 0, models at their spawn poses', flush=True)
            self._anchor()
        steps = int(request.get('multi_step') or 0) or (1 if request.get('step') else 0)
        if steps:
            self.sim.step(steps)
            self._anchor()
        if 'run_to_sim_time' in request:  # ns; run until then, then pause (0: no target)
            target = int(request['run_to_sim_time'] or 0)
            self.run_to = target if target > self.sim.time_ns else None

    def _reached(self) -> None:
        """Pause at a run_to_sim_time target, as Gazebo's runner does."""
        if self.run_to is not None and self.sim.time_ns >= self.run_to:
            self.run_to = None
            self.control({'pause': True})

    def running_time(self, now: float) -> float:
        """Wall seconds spent running (Gazebo's real_time: its watch stops while paused)."""
        return self.run_time + (0.0 if self.paused else now - self.run_since)

    def _anchor(self) -> None:
        """Real time counts again from now (after a pause, a reset, or steps on request)."""
        self.anchor = (time.monotonic(), self.sim.steps)

    def _due(self, now: float) -> int:
        """The step count the absolute schedule asks for at `now`."""
        wall0, steps0 = self.anchor
        return steps0 + int((now - wall0) * self.rate)

    def _stats(self, now: float) -> None:
        """gz.msgs.WorldStatistics on /world/<name>/stats, 10 times a wall second; while
        paused, /clock too (held at the paused time), as Gazebo's loop keeps publishing it."""
        from robot_lab.sim.systems import header, stamp  # imported with the engine, after

        last_wall, last_ns, last_run = self.last_stats
        if now - last_wall < STATS_PERIOD:
            return
        time_ns = self.sim.time_ns
        running = self.running_time(now)
        factor = (time_ns - last_ns) / 1e9 / (running - last_run) if running > last_run else 0.0
        self.last_stats = (now, time_ns, running)
        self.publish(f'/world/{self.sim.info.name}/stats', 'gz.msgs.WorldStatistics', {
            'header': header(time_ns), 'sim_time': stamp(time_ns),
            'real_time': stamp(int(running * 1e9)), 'iterations': self.sim.steps,
            'paused': self.paused, 'real_time_factor': factor,
            'step_size': stamp(self.sim.step_ns), 'model_count': len(self.sim.info.models)
            + len(self.sim.robots)})
        if self.paused:
            self.sim.publish_clock()

    def run(self, rate: float, iterations: int) -> None:
        """Step at `rate` steps per wall second, handling clients' frames between steps."""
        self.rate = rate
        now = time.monotonic()
        self.run_since = now
        self.last_stats = (now - STATS_PERIOD, 0, 0.0)  # the first statistics go out at once
        self._anchor()
        while not iterations or self.sim.steps < iterations:
            now = time.monotonic()
            # the anchor may move while frames are handled (a reset): ask it every step
            while not self.paused and self.sim.steps < self._due(now) and (
                    not iterations or self.sim.steps < iterations):
                self._drain()
                if not self.paused and self.sim.steps < self._due(now):
                    self.sim.step()
                    self._reached()
            self._stats(now)
            if self.paused:
                wait = STATS_PERIOD
            else:
                wall0, steps0 = self.anchor
                wait = (self.sim.steps + 1 - steps0) / rate - (time.monotonic() - wall0)
            try:  # wake for a client's frame, or when the next step is due
                connection, frame = self.inbox.get(timeout=min(max(wait, 0.0), STATS_PERIOD))
                self.handle(connection, frame)
            except queue.Empty:
                pass

    def _drain(self) -> None:
        while True:
            try:
                connection, frame = self.inbox.get_nowait()
            except queue.Empty:
                return
            self.handle(connection, frame)


def _listen(path: Path) -> socket.socket:
    running = connect(path)
    if running is not None:
        running.close()
        raise RobotLabError(f'a simulation already runs in partition {partition()!r} ({path})',
                            fix='stop it first, or set GZ_PARTITION (or ROS_DOMAIN_ID) to '
                                'another value for this one')
    path.unlink(missing_ok=True)  # a socket a killed simulation left
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(str(path))
    listener.listen(16)
    return listener


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(split_gz_args(sys.argv[1:] if argv is None else argv))
    if args.version:
        print(identity())
        return 0
    print(f'[Msg] {identity()}', flush=True)
    for line in _ignored_options(args):
        print(line, flush=True)
    if args.gui:
        print('[Err] gz sim -g (the GUI alone) is not available: robot_lab draws the world in '
              'robot_lab.scene_view() instead', flush=True)
        return 1
    path = socket_path()
    try:  # listen first: `create` and the bridge connect while the engine still loads
        listener = _listen(path)
    except RobotLabError as error:
        print(f'[Err] {error}', flush=True)
        return 1
    try:
        from robot_lab.sim.simulation import Simulation  # MuJoCo: most of the start's time

        sim = Simulation(args.world, seed=args.seed)
    except RobotLabError as error:
        print(f'[Err] {error}', flush=True)
        listener.close()
        path.unlink(missing_ok=True)
        return 1
    info = sim.info
    print(f'[Msg] Loaded world {info.name!r} from {sim.path}: step {info.step * 1000:g} ms, '
          f'real-time factor {info.real_time_factor:g}', flush=True)
    if not args.run:  # Gazebo without -r: paused until its play button (no GUI here)
        print(f'[Msg] Paused, as gz sim starts without -r: start it with  '
              f'{start_command(info.name)}  (from ROS, through parameter_bridge '
              f'/world/{info.name}/control@ros_gz_interfaces/srv/ControlWorld: ros2 service '
              f'call /world/{info.name}/control ros_gz_interfaces/srv/ControlWorld '
              f'"{{world_control: {{pause: false}}}}"), or pass -r to run at once', flush=True)
    print(f'[Msg] Serving partition {partition()!r} on {path}', flush=True)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    rate = args.rate or info.real_time_factor / info.step
    try:
        Server(sim, listener, paused=not args.run).run(rate, args.iterations)
    except KeyboardInterrupt:
        pass
    finally:
        listener.close()
        path.unlink(missing_ok=True)
    return 0


def gzserver_main(argv: Sequence[str] | None = None) -> int:
    """ros_gz_sim's `gzserver` (what gz_server.launch.py runs): the world from its ROS
    parameter world_sdf_file or world_sdf_string, server only, running at once, as
    upstream's runs its server unpaused."""
    import tempfile

    import rclpy
    import rclpy.utilities

    rclpy.init(args=['gzserver', *(sys.argv[1:] if argv is None else argv)])
    node: Any = rclpy.create_node('gz_server',
                                  automatically_declare_parameters_from_overrides=True)
    values = {name: p.value for name, p in node.get_parameters_by_prefix('').items()}
    node.destroy_node()
    rclpy.utilities.try_shutdown()
    if str(values.get('use_composition', '')).lower() == 'true':
        print("[Wrn] use_composition: robot_lab's simulator runs as its own process, not a "
              'component; ignored', flush=True)
    world = str(values.get('world_sdf_file') or '')
    text = str(values.get('world_sdf_string') or '')
    if world or not text:
        return main(['-r', '-s', world or 'empty.sdf'])
    with tempfile.TemporaryDirectory() as folder:  # gz-sim reads the string; the kit a file
        path = Path(folder) / 'world_sdf_string.sdf'
        path.write_text(text)
        return main(['-r', '-s', str(path)])


if __name__ == '__main__':
    sys.exit(main())
