"""Package checks by id: `@register('readme', stage='files')` on a check function.

As a launch action registers its tag, each module of `robot_lab.grading.package.checks`
registers the check it scores, so the ids live in one place (a rubric names them, the
gradebook uses them as columns) and a new check is one module plus one rubric line.
A check function takes the job's state and its rubric entry and returns a `Verdict`;
it runs once its stage is done: 'files' (the package's files), 'build' (colcon), 'run'
(the launched system, observed).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, TypeVar

if TYPE_CHECKING:
    from robot_lab.grading.package.rubric import RubricCheck
    from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['STAGES', 'RegisteredCheck', 'Stage', 'check_ids', 'register', 'registered_checks']

Stage = Literal['files', 'build', 'run']
STAGES: tuple[Stage, ...] = ('files', 'build', 'run')
CheckFunction = Callable[['JobState', 'RubricCheck'], 'Verdict']
# A rubric entry's options -> None, or (the option at fault ('' for the entry), what is
# wrong, how to fix it) for load_rubric's one-line error at that option's line.
OptionsCheck = Callable[[Mapping[str, Any]], 'tuple[str, str, str] | None']
F = TypeVar('F', bound=CheckFunction)
_CHECKS_PACKAGE = 'robot_lab.grading.package.checks'
_REGISTRY: dict[str, RegisteredCheck] = {}


@dataclass(frozen=True)
class RegisteredCheck:
    id: str
    stage: Stage
    run: CheckFunction
    validate: OptionsCheck | None = None


def register(check_id: str, stage: Stage,
             validate: OptionsCheck | None = None) -> Callable[[F], F]:
    """Register the decorated function as the check `check_id`, scored after `stage`;
    `validate` judges a rubric entry's options when the rubric is loaded."""
    if stage not in STAGES:
        raise ValueError(f'stage {stage!r} is not one of {STAGES}')

    def decorate(func: F) -> F:
        known = _REGISTRY.get(check_id)
        if known is not None and known.run is not func:
            raise ValueError(f'check {check_id!r} is registered twice')
        _REGISTRY[check_id] = RegisteredCheck(check_id, stage, func, validate)
        return func

    return decorate


def registered_checks() -> dict[str, RegisteredCheck]:
    """Every check of the kit, by id (importing the checks package registers them)."""
    importlib.import_module(_CHECKS_PACKAGE)
    return dict(_REGISTRY)


def check_ids() -> list[str]:
    return sorted(registered_checks())
