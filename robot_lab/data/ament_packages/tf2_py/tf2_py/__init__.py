"""tf2_py, as robot_lab provides it: geometry2's BufferCore and exceptions, in Python.

The exceptions' names are listed once, in robot_lab.tf2.exceptions; this module and
tf2_ros take that list rather than restating it.
"""

from robot_lab.tf2 import exceptions as _exceptions
from robot_lab.tf2.buffer_core import BufferCore
from robot_lab.tf2.exceptions import *  # noqa: F403

__all__ = ['BufferCore']
__all__ += _exceptions.__all__
