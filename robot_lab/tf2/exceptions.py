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
    """Any tf2 failure. The message is upstream's; `try_hint` says what to do about it
    (a notebook cell's error shows it as its `Try:` line)."""

    @property
    def try_hint(self) -> str:
        return hint(self)


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


def hint(exc: TransformException) -> str:
    """The usual cause of a tf2 error and its fix, in one line."""
    text = str(exc)
    if isinstance(exc, LookupException) and 'does not exist' in text:
        return ('that frame is not in the buffer (yet): a listener needs a moment after it '
                'starts, so give the lookup a timeout, e.g. timeout=rclpy.duration.Duration('
                'seconds=1.0), and check the name against buffer.all_frames_as_string()')
    if isinstance(exc, ExtrapolationException) and 'into the future' in text:
        return ('you asked for a time newer than the newest data: ask for rclpy.time.Time() '
                '(the latest common time), or wait for it with timeout=')
    if isinstance(exc, ExtrapolationException) and 'into the past' in text:
        return ('that time is older than the buffer keeps (10 s) or than its first sample: '
                'ask for a newer time, or rclpy.time.Time() for the latest')
    if isinstance(exc, ExtrapolationException):
        return ('the frame has one sample only, at another time: ask for rclpy.time.Time() '
                '(the latest), or publish the transform regularly')
    if isinstance(exc, ConnectivityException):
        return ('the two frames are in separate trees: a broadcaster of a link between them '
                'is missing (ros2 run tf2_tools view_frames shows the trees)')
    if isinstance(exc, InvalidArgumentException):
        return "frame ids are names without a leading '/' and never empty"
    return ''


# A traceback shows `tf2.LookupException: ...`, as with geometry2's extension module.
for _cls in (TransformException, ConnectivityException, LookupException,
             ExtrapolationException, InvalidArgumentException, TimeoutException):
    _cls.__module__ = 'tf2'
