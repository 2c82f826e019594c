"""What the 3D view hears: which display a topic gets, with which QoS, taken at each tick.

The view's subscriptions live on a node of its own that no executor spins: the view takes
what arrived at each tick. An executor wakes, and rebuilds its wait set in Python, for
every message: /tf at 50 Hz cost the kernel 2.5 % of a core that way. The QoS follows
RViz's: tf2's TransformListener's for /tf and /tf_static, and a display that wants the
last message (RobotModel) asks for it only from publishers that keep one.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.scene.displays import BY_TYPE, Display
from robot_lab.scene.frames import Pose, parse_tf_message

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.qos import QoSProfile
    from rclpy.subscription import Subscription

__all__ = ['TF_TYPE', 'Subscriptions', 'display_for', 'display_qos', 'tf_qos', 'tf_transforms']

TF_TYPE = 'tf2_msgs/msg/TFMessage'
_NAMES = {'robotmodel': 'RobotModel', 'laserscan': 'LaserScan', 'marker': 'Markers',
          'markerarray': 'Markers', 'markers': 'Markers', 'path': 'Path',
          'odometry': 'Odometry', 'pose': 'PoseStamped', 'posestamped': 'PoseStamped'}


def _display_class(kind: str | type[Display]) -> type[Display]:
    if isinstance(kind, type):
        return kind
    from robot_lab.scene import displays

    name = _NAMES.get(kind.lower().replace('_', ''))
    if name is None:
        raise GraphError(f'no display named {kind!r}',
                         fix='use one of RobotModel, LaserScan, Marker, MarkerArray, Path, '
                         'Odometry, Pose')
    cls: type[Display] = getattr(displays, name)
    return cls


def display_for(topic: str, types: list[str], display: str | type[Display] | None,
                options: dict[str, object]) -> Display:
    """RViz's "Add ▸ By topic": the display for `topic`, published as `types`, from its type
    (LaserScan, Marker/MarkerArray, Path, Odometry, PoseStamped) unless `display` names it."""
    if display is None:
        known = [t for t in types if t in BY_TYPE]
        if not known:
            why = (f'its type is {", ".join(types)}' if types
                   else 'nothing publishes it yet')
            raise GraphError(f'cannot tell which display draws {topic}: {why}',
                             fix=f"name it: view.add('{topic}', 'LaserScan') (or Marker, "
                             'MarkerArray, Path, Odometry, Pose)')
        cls = BY_TYPE[known[0]]
    else:
        cls = _display_class(display)
    shown = cls(topic, **options)  # type: ignore[arg-type]
    wanted = [t for t in types if t in shown.type_names]
    if isinstance(display, str) and display.lower() == 'marker':
        shown.type_name = 'visualization_msgs/msg/Marker'
    if wanted:
        shown.type_name = wanted[0]
    return shown


def tf_qos(static: bool) -> QoSProfile:
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    # tf2's TransformListener's QoS: depth 100, /tf_static transient-local
    return QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if static
                      else DurabilityPolicy.VOLATILE)


def display_qos(graph: Node, display: Display) -> QoSProfile:
    """The QoS `display` subscribes with, given the publishers `graph` sees now."""
    from rclpy.qos import (
        DurabilityPolicy,
        QoSProfile,
        ReliabilityPolicy,
        qos_profile_sensor_data,
    )

    if not display.latched:
        return qos_profile_sensor_data  # best effort: hears reliable publishers too
    assert display.topic is not None
    offered = graph.get_publishers_info_by_topic(display.topic)
    every_latched = all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
                        for p in offered)
    # A transient-local publisher's last message reaches a late view (RViz's durability
    # setting); a volatile request matches every publisher. robot_state_publisher's
    # /robot_description is transient-local: assumed before it is up.
    latched = every_latched if offered else display.kind == 'robot_model'
    return QoSProfile(depth=1 if display.kind == 'robot_model' else 100,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                      else DurabilityPolicy.VOLATILE)


def tf_transforms(raw: bytes) -> list[tuple[str, str, Pose]]:
    """A serialized TFMessage's (parent, child, pose) triples."""
    try:
        return parse_tf_message(raw)
    except ValueError:  # an encoding the fast path does not read: rclpy's way
        from rclpy.serialization import deserialize_message

        from robot_lab.messages import message_class

        msg = deserialize_message(raw, message_class(TF_TYPE))
        return [(t.header.frame_id, t.child_frame_id, (
            t.transform.translation.x, t.transform.translation.y,
            t.transform.translation.z, t.transform.rotation.x, t.transform.rotation.y,
            t.transform.rotation.z, t.transform.rotation.w)) for t in msg.transforms]


class Subscriptions:
    """The view's subscriptions by key, on `node` (spun by nobody); `take` empties them."""

    def __init__(self, node: Node, closed: threading.Event) -> None:
        self._node = node
        self._closed = closed
        # key → (subscription, what takes its message, raw bytes wanted)
        self._subscriptions: dict[str, tuple[Subscription, Callable[[Any], None], bool]] = {}
        self._lock = threading.Lock()

    def add(self, key: str, type_name: str, topic: str, qos: QoSProfile,
            take: Callable[[Any], None], raw: bool = False) -> None:
        from robot_lab.messages import message_class

        cls = message_class(type_name)
        with self._lock:
            subscription = self._node.create_subscription(cls, topic, lambda _m: None, qos)
            self._subscriptions[key] = (subscription, take, raw)

    def remove(self, key: str) -> None:
        with self._lock:
            found = self._subscriptions.pop(key, None)
            if found is not None:
                self._node.destroy_subscription(found[0])

    def take(self) -> None:
        """Take every message that has arrived since the last tick."""
        with self._lock:
            for subscription, take, raw in self._subscriptions.values():
                with subscription.handle:
                    while not self._closed.is_set():
                        taken = subscription.handle.take_message(subscription.msg_type, raw)
                        if taken is None:
                            break
                        take(taken[0])

    def close(self) -> None:
        """Drop every subscription and the node."""
        with self._lock:
            self._subscriptions.clear()
            self._node.destroy_node()
