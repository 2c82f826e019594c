"""tf2's Python exceptions, named as tf2_py names them (`tf2.LookupException`, ...).

tf2_ros re-exports them; a student's `except tf2_ros.TransformException` catches all five.
"""

from __future__ import annotations

__all__ = [
    'ConnectivityException',
    'ExtrapolationException',
    'InvalidArgumentException',
    'LookupException',
    'TimeoutException',
    'TransformException',
]


class TransformException(Exception):  # noqa: N818 (upstream's name)
    """Any tf2 failure."""


class ConnectivityException(TransformException):
    """The two frames are in different trees."""


class LookupException(TransformException):
    """A frame that does not exist (or a loop in the tree)."""


class ExtrapolationException(TransformException):
    """The time asked is outside the data (past, future, or a single sample)."""


class InvalidArgumentException(TransformException):
    """An empty frame id, or one starting with '/'."""


class TimeoutException(TransformException):
    """A wait for a transform ran out."""


# A traceback shows `tf2.LookupException: ...`, as with geometry2's extension module.
for _cls in (TransformException, ConnectivityException, LookupException,
             ExtrapolationException, InvalidArgumentException, TimeoutException):
    _cls.__module__ = 'tf2'
