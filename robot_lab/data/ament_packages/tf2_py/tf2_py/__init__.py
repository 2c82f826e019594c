"""tf2_py, as robot_lab provides it: geometry2's BufferCore and exceptions, in Python."""

from robot_lab.tf2.buffer_core import BufferCore
from robot_lab.tf2.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

__all__ = [
    'BufferCore',
    'ConnectivityException',
    'ExtrapolationException',
    'InvalidArgumentException',
    'LookupException',
    'TimeoutException',
    'TransformException',
]
