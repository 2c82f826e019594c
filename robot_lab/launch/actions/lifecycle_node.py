"""launch_ros.actions.LifecycleNode: a node whose state transitions launch can drive.

Its process starts like any node; the supervisor then watches the node's
`transition_event` topic (StateTransition events for OnStateTransition handlers) and
carries out EmitEvent(ChangeState(...)) and `autostart=True` (configure, then activate)
through the node's `change_state` service (see lifecycle_bridge.py).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robot_lab.launch.actions.node import NodeStep
from robot_lab.launch.entity import Entity
from robot_lab.launch.plan import ProcessSpec
from robot_lab.launch.registry import register

if TYPE_CHECKING:
    from robot_lab.launch.action import LaunchStep
    from robot_lab.launch.context import LaunchContext

__all__ = ['LifecycleNodeStep']


@register('lifecycle_node')
class LifecycleNodeStep(NodeStep):
    """A Node with a lifecycle (launch_ros requires its name and namespace)."""

    launch_name = 'LifecycleNode'

    def __init__(self, executable: Any, *, autostart: bool = False, **kwargs: Any) -> None:
        super().__init__(executable, **kwargs)
        if self.name is None:
            raise TypeError("LifecycleNode needs name='...': launch drives it by its name")
        self.autostart = autostart

    def execute(self, context: LaunchContext) -> None:
        super().execute(context)
        spec = next(a for a in reversed(context.sink)
                    if isinstance(a, ProcessSpec) and a.origin is self)
        spec.lifecycle = 'autostart' if self.autostart else 'manual'

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        autostart = e.attr('autostart', 'bool')
        node = super().parse(e)
        assert isinstance(node, LifecycleNodeStep)
        node.autostart = bool(autostart)
        return node
