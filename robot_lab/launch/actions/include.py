"""`<include>`/IncludeLaunchDescription, and the arguments a description declares."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchDescriptionStep, LaunchStep, subs
from robot_lab.launch.actions.arguments import DeclareArgumentStep
from robot_lab.launch.actions.timer import TimerStep
from robot_lab.launch.entity import Entity, required
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['IncludeStep', 'declared_arguments']


@register('include')
class IncludeStep(LaunchStep):
    """`<include>` / IncludeLaunchDescription: not scoped; arguments become configurations."""

    launch_name = 'IncludeLaunchDescription'

    def __init__(self, path: SomeSubstitutions,
                 arguments: Iterable[tuple[SomeSubstitutions, SomeSubstitutions]] = (),
                 loader: Callable[[Path], LaunchDescriptionStep] | None = None) -> None:
        self.path = subs(path)
        self.arguments = [(subs(n), subs(v)) for n, v in arguments]
        self.loader = loader

    def execute(self, context: LaunchContext) -> None:
        path = Path(os.path.abspath(perform(self.path, context)))
        if not path.is_file():
            raise context.error(f'included launch file not found: {path}',
                                fix='check the path; relative paths resolve against the '
                                'current directory, use $(dirname)/file for a sibling file')
        chain = [*context.files, path]
        if path in context.files:
            cycle = ' -> '.join(p.name for p in chain[chain.index(path):])
            raise context.error(f'include cycle: {cycle}',
                                fix='remove one of the includes (or guard it with if=)')
        names = [perform(n, context) for n, _ in self.arguments]
        values = [perform(v, context) for _, v in self.arguments]
        description = (self.loader or context.load_launch_file)(path)
        given = set(names)
        for declared in declared_arguments(description, conditional_ok=False):
            if declared.default is None and declared.name not in given:
                raise context.error(
                    f"Included launch description missing required argument '{declared.name}' "
                    f"(description: '{declared.description}'), given: [{', '.join(names)}]",
                    fix=f'add <arg name="{declared.name}" value="..."/> to the include')
        context.configurations.update(zip(names, values, strict=True))
        context.files.append(path)
        try:
            context.run([description])
        finally:
            context.files.pop()

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        args = e.entities('arg') or []
        pairs = [(required(a, 'name'), required(a, 'value')) for a in args]
        for a in args:
            a.assert_parsed()
        return cls(required(e, 'file'), pairs)


def declared_arguments(step: LaunchStep, conditional_ok: bool = True) -> list[DeclareArgumentStep]:
    """Declared arguments reachable without executing (as launch's get_launch_arguments)."""
    found: list[DeclareArgumentStep] = []

    def walk(node: LaunchStep, conditional: bool) -> None:
        conditional = conditional or node.condition is not None
        if isinstance(node, DeclareArgumentStep):
            if (conditional_ok or not conditional) and all(d.name != node.name for d in found):
                found.append(node)
            return
        if isinstance(node, IncludeStep | TimerStep):
            return
        for child in node.children():
            walk(child, conditional)

    walk(step, False)
    return found
