"""Messages of types the grader does not load, read and written by a helper process.

A student's own interface package (`lamp_interfaces/msg/LampCommand`) is built in the job's
workspace. Importing its generated modules and their C type support would run code of the
student's in the grader's process, which holds the report pipe: so the grader loads only
the kit's types (robot_lab.grading.package.live keeps the workspace off its sys.path), and
this helper, started with the workspace's environment, subscribes and publishes the others.
They travel as message dicts (robot_lab.messages), one JSON line each:

- grader → helper: `{"op": "sub"|"pub", "topic", "type"}`, `{"op": "send", "topic", "data"}`;
- helper → grader: `{"topic", "data"}` per message received, `{"op": "matched", "topic",
  "count"}` when a publisher's subscriber count changes, `{"op": "error", "topic", "error"}`.

`python -m robot_lab.grading.package.bridge` is the helper; `Bridge` is the grader's side.
"""

from __future__ import annotations

import contextlib
import functools
import json
import subprocess
import sys
import threading
from collections.abc import Callable
from typing import IO, Any

__all__ = ['Bridge', 'main']

Handler = Callable[[dict[str, Any]], None]


class Bridge:
    """The grader's side: a lazily started helper; a handler per subscribed topic."""

    def __init__(self) -> None:
        self._proc: subprocess.Popen[bytes] | None = None
        self._lock = threading.Lock()
        self._handlers: dict[str, Handler] = {}
        self._subscribed: set[str] = set()
        self._advertised: set[str] = set()
        self.matched: dict[str, int] = {}
        self.errors: dict[str, str] = {}

    def _send(self, message: dict[str, Any]) -> None:
        with self._lock:
            if self._proc is None:
                from robot_lab.process import spawn

                self._proc = spawn([sys.executable, '-m', __name__], stdin=subprocess.PIPE,
                                   stdout=subprocess.PIPE, stderr=None)
                threading.Thread(target=self._read, args=(self._proc.stdout,),
                                 daemon=True).start()
            assert self._proc.stdin is not None
            try:
                self._proc.stdin.write((json.dumps(message) + '\n').encode())
                self._proc.stdin.flush()
            except OSError as err:  # the helper died: what it was asked for stays unheard
                self.errors[message.get('topic', '')] = f'the helper has exited: {err}'

    def _read(self, stream: IO[bytes] | None) -> None:
        assert stream is not None
        for raw in stream:
            try:
                line = json.loads(raw)
            except ValueError:
                continue
            topic = str(line.get('topic', ''))
            op = line.get('op')
            if op == 'matched':
                self.matched[topic] = int(line.get('count', 0))
            elif op == 'error':
                self.errors[topic] = str(line.get('error', ''))
            elif isinstance(line.get('data'), dict):
                handler = self._handlers.get(topic)
                if handler is not None:
                    handler(line['data'])

    def subscribe(self, topic: str, type_name: str, handler: Handler) -> None:
        """Call `handler(message dict)` for each message on `topic` (until `unsubscribe`)."""
        self._handlers[topic] = handler
        if topic not in self._subscribed:
            self._subscribed.add(topic)
            self._send({'op': 'sub', 'topic': topic, 'type': type_name})

    def unsubscribe(self, topic: str) -> None:
        self._handlers.pop(topic, None)

    def advertise(self, topic: str, type_name: str) -> None:
        if topic not in self._advertised:
            self._advertised.add(topic)
            self._send({'op': 'pub', 'topic': topic, 'type': type_name})

    def publish(self, topic: str, data: dict[str, Any]) -> None:
        self._send({'op': 'send', 'topic': topic, 'data': data})

    def failed(self) -> str:
        """Why the helper stopped serving before `close()` ('' while it serves)."""
        with self._lock:
            proc = self._proc
        if proc is not None and proc.poll() is not None:
            return f"the grader's message helper exited with code {proc.returncode}"
        return ''

    def close(self) -> None:
        with self._lock:
            proc, self._proc = self._proc, None
        if proc is None:
            return
        with contextlib.suppress(OSError):
            assert proc.stdin is not None
            proc.stdin.close()  # the helper ends at the end of its input
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def main() -> int:
    """The helper: serve the grader's requests on stdin until it closes."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, QoSReliabilityPolicy

    from robot_lab.messages import message_class, message_from_yaml, message_to_dict

    out = sys.stdout.buffer
    out_lock = threading.Lock()

    def say(message: dict[str, Any]) -> None:
        with out_lock:
            out.write((json.dumps(message, default=str) + '\n').encode())
            out.flush()

    rclpy.init(args=[])
    node = rclpy.create_node('_robot_lab_grader_bridge')
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    publishers: dict[str, Any] = {}
    counts: dict[str, int] = {}
    entities_lock = threading.Lock()

    def on_message(topic: str, msg: Any) -> None:
        with contextlib.suppress(Exception):
            say({'topic': topic, 'data': message_to_dict(msg)})

    def report_matches() -> None:
        with entities_lock:
            for topic, pub in publishers.items():
                count = pub.get_subscription_count()
                if counts.get(topic) != count:
                    counts[topic] = count
                    say({'op': 'matched', 'topic': topic, 'count': count})

    node.create_timer(0.05, report_matches)
    threading.Thread(target=executor.spin, daemon=True).start()
    classes: dict[str, Any] = {}
    qos = QoSProfile(depth=50, reliability=QoSReliabilityPolicy.BEST_EFFORT)
    for raw in sys.stdin.buffer:
        request: dict[str, Any] = {}
        try:
            request = json.loads(raw)
            topic = str(request['topic'])
            op = request['op']
            if op in ('sub', 'pub'):
                cls = message_class(str(request['type']))
                classes[topic] = cls
                with entities_lock:
                    if op == 'sub':
                        node.create_subscription(
                            cls, topic, functools.partial(on_message, topic), qos)
                    else:
                        publishers[topic] = node.create_publisher(cls, topic, 10)
            elif op == 'send':
                publishers[topic].publish(message_from_yaml(classes[topic], request['data']))
        except Exception as err:  # a type the workspace does not have either, bad data
            say({'op': 'error', 'topic': str(request.get('topic', '')),
                 'error': f'{type(err).__name__}: {err}'})
    executor.shutdown(timeout_sec=1)
    node.destroy_node()
    with contextlib.suppress(Exception):
        rclpy.shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
