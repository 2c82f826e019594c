"""tf2_ros.buffer_interface (robot_lab.tf2.buffer)."""

from robot_lab.tf2.buffer import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    Stamped,
    TransformRegistration,
    TypeException,
    convert,
)

__all__ = [
    'BufferInterface',
    'ConvertRegistration',
    'NotImplementedException',
    'Stamped',
    'TransformRegistration',
    'TypeException',
    'convert',
]
