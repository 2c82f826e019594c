"""The TF tree of the student's running system, heard as a tf2 listener hears it.

The watch (roles.observe) subscribes best-effort and volatile, so it never gets
robot_state_publisher's one transient-local `/tf_static` message, sent at start-up. A
tf2_ros TransformListener subscribes with upstream's QoS (`/tf_static` transient-local,
depth 100): it gets the fixed joints whenever it joins. Its buffer here only records the
edges (parent → child, static or not), for the `tf_tree` check
(robot_lab.grading.package.checks.description): a frame given two parents is a mistake the
tf2 buffer would hide by keeping the latest one.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robot_lab.rclpy_session import Session

__all__ = ['TfEdge', 'TfWatch']


@dataclass(frozen=True)
class TfEdge:
    parent: str
    child: str
    static: bool  # heard on /tf_static


class _EdgeRecorder:
    """What TransformListener calls a buffer: `set_transform(_static)` per transform."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.edges: set[TfEdge] = set()

    def _add(self, transform: Any, static: bool) -> None:
        edge = TfEdge(str(transform.header.frame_id).lstrip('/'),
                      str(transform.child_frame_id).lstrip('/'), static)
        with self.lock:
            self.edges.add(edge)

    def set_transform(self, transform: Any, authority: str) -> None:
        self._add(transform, False)

    def set_transform_static(self, transform: Any, authority: str) -> None:
        self._add(transform, True)


class TfWatch:
    """A tf2 listener on the observer session's node, from now until `close()`."""

    def __init__(self, sess: Session) -> None:
        from robot_lab.tf2.listener import TransformListener

        self._recorder = _EdgeRecorder()
        self._listener = TransformListener(self._recorder, sess.node)

    def edges(self) -> set[TfEdge]:
        """Every parent → child heard so far (on /tf and on /tf_static)."""
        with self._recorder.lock:
            return set(self._recorder.edges)

    def close(self) -> None:
        self._listener.unregister()
