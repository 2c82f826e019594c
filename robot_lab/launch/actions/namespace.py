"""`<push-ros-namespace>`/PushROSNamespace."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, subs
from robot_lab.launch.entity import Entity, required
from robot_lab.launch.names import absolute_namespace, namespace_problem, prefix_namespace
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['PushNamespaceStep']


@register('push-ros-namespace', 'push_ros_namespace')
class PushNamespaceStep(LaunchStep):
    """`<push-ros-namespace>` / PushROSNamespace: relative values nest, absolute replace."""

    launch_name = 'PushROSNamespace'

    def __init__(self, namespace: SomeSubstitutions) -> None:
        self.namespace = subs(namespace)

    def execute(self, context: LaunchContext) -> None:
        pushed = perform(self.namespace, context)
        previous = context.ros['ros_namespace']
        namespace = absolute_namespace(prefix_namespace(previous, pushed))
        assert namespace is not None
        problem = namespace_problem(namespace)
        if problem:
            raise context.error(
                f"The resulting namespace is invalid: [previous_namespace='{previous}', "
                f"pushed_namespace='{pushed}'] ({problem})")
        context.ros['ros_namespace'] = namespace

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        return cls(required(e, 'namespace'))
