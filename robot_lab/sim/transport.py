"""The simulator's own topics, apart from ROS: gz-transport's role, over one Unix socket.

In Gazebo nothing the simulator publishes is a ROS topic until `ros_gz_bridge` makes it one;
the kit keeps that boundary. The simulator listens on a Unix stream socket of the user's
own (`$XDG_RUNTIME_DIR/robot_lab/gz-<partition>-net<namespace>.sock`, else
`/tmp/robot_lab-<uid>/`, the folder mode 0700), one per partition: GZ_PARTITION if set (as
gz-transport scopes its discovery), else the ROS domain (`domain<ROS_DOMAIN_ID>`), so two
students' simulations, and a test's, never meet. And one per network namespace: Gazebo's
discovery goes by the network, so a simulation in another namespace (a grading job, a
second test run beside this one) is not this one's, as its DDS traffic is not.
Each frame is a 4-byte big-endian length and a JSON object:
- client → simulator: `{"op": "sub", "topic"}`, `{"op": "pub", "topic", "type", "msg"}`,
  `{"op": "create", "id", "urdf", "name", "xyz", "rpy", "source"}`, `{"op": "topics", "id"}`;
- simulator → client: `{"op": "msg", "topic", "type", "msg"}`, `{"op": "reply", "id", "ok",
  "error", "data"}`.
Messages are gz.msgs-shaped dicts (see `systems`); JSON keeps inf ranges as `Infinity`.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import struct
import threading
from pathlib import Path
from typing import Any

from robot_lab.linux import procfs

__all__ = ['Connection', 'connect', 'partition', 'socket_path', 'topic_name']

Frame = dict[str, Any]
_LENGTH = struct.Struct('>I')


def topic_name(name: str) -> str:
    """gz-transport's fully qualified topic: relative names start at the root."""
    return name if name.startswith('/') else '/' + name


def partition(env: dict[str, str] | None = None) -> str:
    """GZ_PARTITION, else the ROS domain: which simulation a command or bridge talks to."""
    env = dict(os.environ) if env is None else env
    return env.get('GZ_PARTITION') or f'domain{env.get("ROS_DOMAIN_ID") or "0"}'


def socket_path(env: dict[str, str] | None = None) -> Path:
    """The partition's socket, in a folder only this user can enter."""
    env = dict(os.environ) if env is None else env
    runtime = env.get('XDG_RUNTIME_DIR')
    folder = (Path(runtime) / 'robot_lab' if runtime and Path(runtime).is_dir()
              else Path('/tmp') / f'robot_lab-{os.getuid()}')
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    name = ''.join(c if c.isalnum() or c in '-_.' else '_' for c in partition(env))
    network = procfs.net_namespace()
    return folder / (f'gz-{name}-net{network}.sock' if network else f'gz-{name}.sock')


class Connection:
    """One end of a framed JSON stream; `send` is safe from any thread."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self._send_lock = threading.Lock()
        self._buffer = b''
        self.closed = False

    def send(self, frame: Frame) -> bool:
        """Send a frame; False if the other end has gone."""
        data = json.dumps(frame, separators=(',', ':')).encode()
        try:
            with self._send_lock:
                self.sock.sendall(_LENGTH.pack(len(data)) + data)
        except OSError:
            self.closed = True
            return False
        return True

    def receive(self) -> Frame | None:
        """The next frame, or None when the other end has closed."""
        while True:
            if len(self._buffer) >= _LENGTH.size:
                (length,) = _LENGTH.unpack_from(self._buffer)
                if len(self._buffer) >= _LENGTH.size + length:
                    body = self._buffer[_LENGTH.size:_LENGTH.size + length]
                    self._buffer = self._buffer[_LENGTH.size + length:]
                    frame: Frame = json.loads(body)
                    return frame
            try:
                chunk = self.sock.recv(65536)
            except OSError:
                chunk = b''
            if not chunk:
                self.closed = True
                return None
            self._buffer += chunk

    def close(self) -> None:
        self.closed = True
        with contextlib.suppress(OSError):
            self.sock.shutdown(socket.SHUT_RDWR)
        self.sock.close()


def connect(path: Path | None = None) -> Connection | None:
    """A connection to the running simulation, or None if none listens on the socket."""
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.connect(str(path or socket_path()))
    except OSError:
        sock.close()
        return None
    return Connection(sock)
