"""tf2_ros's TransformBroadcaster (/tf, depth 100) and StaticTransformBroadcaster
(/tf_static, depth 1 transient-local: it republishes every static frame it has sent, so
one latched message holds them all)."""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

__all__ = ['StaticTransformBroadcaster', 'TransformBroadcaster']


def _as_list(transform: Any) -> list[Any]:
    if isinstance(transform, list):
        return transform
    if hasattr(transform, '__iter__'):
        return list(transform)
    return [transform]


class TransformBroadcaster:
    """`TransformBroadcaster(node, qos=None)`; `sendTransform(t or [t, ...])`."""

    def __init__(self, node: Any, qos: QoSProfile | int | None = None) -> None:
        from tf2_msgs.msg import TFMessage
        self._message = TFMessage
        if qos is None:
            qos = QoSProfile(depth=100)
        self.pub_tf = node.create_publisher(TFMessage, '/tf', qos)

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 (upstream's name)
        self.pub_tf.publish(self._message(transforms=_as_list(transform)))


class StaticTransformBroadcaster:
    """`StaticTransformBroadcaster(node, qos=None)`; each child frame is kept once (the
    first transform sent for it), and all of them go out on every send, as upstream."""

    def __init__(self, node: Any, qos: QoSProfile | int | None = None) -> None:
        from tf2_msgs.msg import TFMessage
        if qos is None:
            qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                             history=HistoryPolicy.KEEP_LAST)
        self.pub_tf = node.create_publisher(TFMessage, '/tf_static', qos)
        self.net_message = TFMessage()
        self._child_frame_ids: set[str] = set()

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 (upstream's name)
        for t_in in _as_list(transform):
            if t_in.child_frame_id not in self._child_frame_ids:
                self._child_frame_ids.add(t_in.child_frame_id)
                self.net_message.transforms.append(t_in)
        self.pub_tf.publish(self.net_message)
