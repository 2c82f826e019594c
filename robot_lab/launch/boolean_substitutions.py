"""Boolean and comparison substitutions: `$(if)`, `$(not)`, `$(and)`, `$(or)`, `$(any)`,
`$(all)`, `$(equals)`, `$(not-equals)` (launch's boolean_substitution.py and friends)."""

from __future__ import annotations

import math

from robot_lab.launch.substitutions import (
    Subs,
    Substitution,
    SubstitutionContext,
    coerce,
    perform,
)

__all__ = ['AllTrue', 'And', 'AnyTrue', 'Equals', 'IfElse', 'Not', 'NotEquals', 'Or']


def _bool(subs: Subs, context: SubstitutionContext) -> bool:
    value = coerce(perform(subs, context), 'bool')
    assert isinstance(value, bool)
    return value


class IfElse(Substitution):
    """`$(if cond then [else])`."""

    def __init__(self, condition: Subs, if_value: Subs, else_value: Subs | None = None) -> None:
        self.condition, self.if_value, self.else_value = condition, if_value, else_value or []

    def perform(self, context: SubstitutionContext) -> str:
        chosen = self.if_value if _bool(self.condition, context) else self.else_value
        return perform(chosen, context)


class Not(Substitution):
    """`$(not value)`."""

    def __init__(self, value: Subs) -> None:
        self.value = value

    def perform(self, context: SubstitutionContext) -> str:
        return str(not _bool(self.value, context)).lower()


class And(Substitution):
    """`$(and a b)`."""

    def __init__(self, left: Subs, right: Subs) -> None:
        self.left, self.right = left, right

    def perform(self, context: SubstitutionContext) -> str:
        return str(_bool(self.left, context) and _bool(self.right, context)).lower()


class Or(And):
    """`$(or a b)`."""

    def perform(self, context: SubstitutionContext) -> str:
        return str(_bool(self.left, context) or _bool(self.right, context)).lower()


def _is_bool(text: str) -> bool:
    return text.lower() in ('true', 'false', '1', '0')


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


class Equals(Substitution):
    """`$(equals a b)`: booleans and numbers compared by value, else as text."""

    def __init__(self, left: Subs, right: Subs) -> None:
        self.left, self.right = left, right

    def perform(self, context: SubstitutionContext) -> str:
        left, right = perform(self.left, context), perform(self.right, context)
        if _is_bool(left) and _is_bool(right):
            same = (left.lower() in ('true', '1')) == (right.lower() in ('true', '1'))
        elif _is_float(left) and _is_float(right):
            same = math.isclose(float(left), float(right))
        else:
            same = left == right
        return str(same).lower()


class NotEquals(Equals):
    """`$(not-equals a b)`."""

    def perform(self, context: SubstitutionContext) -> str:
        return 'false' if super().perform(context) == 'true' else 'true'


class AnyTrue(Substitution):
    """`$(any a b ...)`: 'true' if at least one argument is true."""

    launch_name = 'AnySubstitution'

    def __init__(self, *args: Subs) -> None:
        self.args = list(args)

    def perform(self, context: SubstitutionContext) -> str:
        return str(any([_bool(arg, context) for arg in self.args])).lower()

    def describe(self) -> str:
        parts = (' + '.join(sub.describe() for sub in arg) for arg in self.args)
        return f'{self.launch_name}({", ".join(parts)})'


class AllTrue(AnyTrue):
    """`$(all a b ...)`: 'true' if every argument is true."""

    launch_name = 'AllSubstitution'

    def perform(self, context: SubstitutionContext) -> str:
        return str(all([_bool(arg, context) for arg in self.args])).lower()
