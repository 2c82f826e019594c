"""Packages: the ament index (find packages and executables), create, build, doctor.

Importing this package loads nothing else (the launcher needs only `index`, and every
millisecond before its first node starts counts); the names below resolve on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

_HOMES = {
    'ament_prefixes': 'index',
    'create_package': 'create',
    'executables': 'index',
    'find_executable': 'index',
    'kit_prefix': 'index',
    'package_prefix': 'index',
    'package_share': 'index',
    'packages': 'index',
    'use_workspace': 'workspace',
    'workspace_dir': 'workspace',
}

__all__ = sorted(_HOMES)


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
    return getattr(importlib.import_module(f'robot_lab.pkg.{home}'), name)
