"""Notebook widgets that make ROS visible: rqt_plot, rqt_reconfigure, rqt_console, a launch panel,
a teleop pad.

Each widget is also drivable from code (`.data`, `.set()`, `.lines()`, `.start()`), so
check cells, tests and headless nbval runs use exactly what students click. Importing
this package is cheap; each widget loads its module (and ipywidgets) on first use.
"""

from __future__ import annotations

import importlib

__all__ = ['console', 'launch_panel', 'plot', 'robot_view', 'sliders', 'teleop',
           'turtlesim_view']

_HOMES = {
    'plot': 'robot_lab.widgets.plot',
    'sliders': 'robot_lab.widgets.sliders',
    'console': 'robot_lab.widgets.console',
    'launch_panel': 'robot_lab.widgets.launch_panel',
    'robot_view': 'robot_lab.widgets.robot_view',
    'turtlesim_view': 'robot_lab.widgets.turtlesim_view',
    'teleop': 'robot_lab.widgets.teleop',
}


def __getattr__(name: str) -> object:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f'module robot_lab.widgets has no attribute {name!r}')
    value = getattr(importlib.import_module(home), name)
    # Importing robot_lab.widgets.<name> made the submodule this package's attribute
    # <name>: without this the second `widgets.plot` was the module, not the function.
    globals()[name] = value
    return value
