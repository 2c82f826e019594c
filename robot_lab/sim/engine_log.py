"""MuJoCo's own warnings, said through the kit instead of a MUJOCO_LOG.TXT in the student's folder.

Without a handler, MuJoCo's C library appends each warning to `MUJOCO_LOG.TXT` in the
current directory (and prints it): a student's notebook folder fills with a file they never
asked for. The Python bindings let one process-wide handler take the warnings instead (its
errors already become `mujoco.FatalError`). The handler is global, so each simulation says
"this is my model" before it calls the engine (`speak_for`), and a warning becomes one line
naming that model on the simulation's own warning path; with no simulation named, the
`robot_lab.sim` logger says it.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

__all__ = ['install', 'speak_for']

Warn = Callable[[str], None]
_LOGGER = logging.getLogger('robot_lab.sim')
_speaker: tuple[str, Warn] | None = None  # the model whose engine calls run now, and its path


def _log(line: str) -> None:
    _LOGGER.warning(line)


def _on_warning(message: str) -> None:
    """MuJoCo calls this for every warning (a C callback: it must never raise)."""
    name, warn = _speaker or ('a MuJoCo model', _log)
    line = f'MuJoCo warning in {name}: {" ".join(str(message).split())}'
    try:
        warn(line)
    except Exception:  # a broken warn path must not turn a warning into a crash in C
        _log(line)


def install() -> None:
    """Take MuJoCo's warnings for this process (idempotent; the first call does it)."""
    if mujoco.get_mju_user_warning() is not _on_warning:
        mujoco.set_mju_user_warning(_on_warning)


def speak_for(name: str, warn: Warn) -> None:
    """Name the model the next engine calls belong to, and where its warnings go.

    A plain assignment, cheap enough for every step: the simulations of one process step
    in one thread, one at a time.
    """
    global _speaker
    _speaker = (name, warn)


install()
