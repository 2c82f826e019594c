"""`xacro`: PyPI's xacro 2.1.1, with `$(find pkg)` resolved through the kit's ament index.

xacro finds a package with ament_index_python, which reads AMENT_PREFIX_PATH; in a kit
terminal that has not sourced the venv's setup.bash it is unset, and `$(find
urdf_tutorial)` failed with "Environment variable 'AMENT_PREFIX_PATH' is not set or
empty". The venv's `xacro` is this wrapper: the user's prefixes first, then the kit's
and the venv's (robot_lab.ament_prefix), as every ROS process the kit starts sees them.
"""

from __future__ import annotations

import os

from robot_lab.ament_prefix import ament_prefixes

__all__ = ['kit_ament_prefix_path', 'main']


def kit_ament_prefix_path() -> str:
    """AMENT_PREFIX_PATH as the kit's children get it (the user's entries kept first)."""
    return os.pathsep.join(str(prefix) for prefix in ament_prefixes())


def main() -> None:
    """The `xacro` console script: set the prefix path, then run xacro's own main."""
    os.environ['AMENT_PREFIX_PATH'] = kit_ament_prefix_path()
    import xacro

    xacro.main()


if __name__ == '__main__':
    main()
