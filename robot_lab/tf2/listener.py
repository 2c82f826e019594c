"""tf2_ros's TransformListener: /tf and /tf_static into a Buffer, with upstream's QoS
(/tf depth 100 volatile, /tf_static depth 100 transient-local, so a late listener still
gets every static frame) and its callbacks in a reentrant group."""

from __future__ import annotations

from threading import Lock, Thread
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

from robot_lab.tf2.buffer import Buffer

__all__ = ['SessionBuffer', 'TransformListener', 'tf_buffer']


class TransformListener:
    """`TransformListener(buffer, node, *, spin_thread=False, qos=None, static_qos=None)`."""

    def __init__(self, buffer: Any, node: Any, *, spin_thread: bool = False,
                 qos: QoSProfile | int | None = None,
                 static_qos: QoSProfile | int | None = None) -> None:
        from tf2_msgs.msg import TFMessage
        if qos is None:
            qos = QoSProfile(depth=100, durability=DurabilityPolicy.VOLATILE,
                             history=HistoryPolicy.KEEP_LAST)
        if static_qos is None:
            static_qos = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                                    history=HistoryPolicy.KEEP_LAST)
        self.buffer = buffer
        self.node = node
        # The default group is mutually exclusive: a callback waiting for a transform would
        # keep these from running.
        self.group = ReentrantCallbackGroup()
        self.tf_sub = node.create_subscription(TFMessage, '/tf', self.callback, qos,
                                               callback_group=self.group)
        self.tf_static_sub = node.create_subscription(
            TFMessage, '/tf_static', self.static_callback, static_qos,
            callback_group=self.group)
        if spin_thread:
            self.executor = SingleThreadedExecutor()

            def run_func() -> None:
                self.executor.add_node(self.node)
                self.executor.spin()
                self.executor.remove_node(self.node)

            self.dedicated_listener_thread = Thread(target=run_func, daemon=True)
            self.dedicated_listener_thread.start()

    def __del__(self) -> None:
        if hasattr(self, 'dedicated_listener_thread') and hasattr(self, 'executor'):
            self.executor.shutdown()
            self.dedicated_listener_thread.join()
        self.unregister()

    def unregister(self) -> None:
        """Destroy the two subscriptions."""
        try:
            self.node.destroy_subscription(self.tf_sub)
            self.node.destroy_subscription(self.tf_static_sub)
        except Exception:  # the node may be gone already (__del__ at shutdown)
            pass

    def callback(self, data: Any) -> None:
        who = 'default_authority'
        for transform in data.transforms:
            self.buffer.set_transform(transform, who)

    def static_callback(self, data: Any) -> None:
        who = 'default_authority'
        for transform in data.transforms:
            self.buffer.set_transform_static(transform, who)


_SESSION_BUFFERS: dict[int, Any] = {}
_SESSION_LOCK = Lock()


class SessionBuffer(Buffer):
    """`tf_buffer()`'s Buffer, with `close()`: a kernel that is done with transforms can
    stop its hidden listener node (a cell's "nothing left running" then holds)."""

    def close(self) -> None:
        """Stop listening (idempotent); the next `tf_buffer()` starts a fresh buffer.

        One buffer serves the whole session, so anything else holding it stops hearing
        /tf too; call `tf_buffer()` again for a filled one.
        """
        with _SESSION_LOCK:
            key = next((k for k, held in _SESSION_BUFFERS.items() if held[1] is self), None)
            held = _SESSION_BUFFERS.pop(key) if key is not None else None
        if held is None:
            return
        sess, _, listener, node = held
        if sess.ok:
            sess.remove_node(node)  # waits until its executor no longer holds the node
        listener.unregister()
        node.destroy_node()


def tf_buffer() -> SessionBuffer:
    """In a notebook: a tf2_ros Buffer that the kernel's session keeps filled from /tf and
    /tf_static (one per session; a hidden node listens, until `close()`), for
    `lookup_transform` in a cell without writing a node first."""
    import os

    from robot_lab.rclpy_session import session

    sess = session()
    with _SESSION_LOCK:
        held = _SESSION_BUFFERS.get(id(sess))
        if held is not None and held[0] is sess:
            buffer: SessionBuffer = held[1]
            return buffer
        node = sess.hidden_node(f'tf_{os.getpid()}')
        buffer = SessionBuffer(node=None)
        listener = TransformListener(buffer, node)
        sess.add_node(node)
        _SESSION_BUFFERS[id(sess)] = (sess, buffer, listener, node)
    return buffer
