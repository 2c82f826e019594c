"""tf2_ros, as robot_lab provides it (robot_lab.tf2), with geometry2's module paths.

tf2_py's names and the buffer interface's come with their own lists (`__all__`), so a
name added there is exported here too, without a second list to keep in step.
"""

import tf2_py as _tf2_py
from tf2_py import *  # noqa: F403

from tf2_ros import buffer_interface as _buffer_interface
from tf2_ros.buffer import Buffer
from tf2_ros.buffer_client import BufferClient
from tf2_ros.buffer_interface import *  # noqa: F403
from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster
from tf2_ros.transform_broadcaster import TransformBroadcaster
from tf2_ros.transform_listener import TransformListener

__all__ = [
    'Buffer',
    'BufferClient',
    'StaticTransformBroadcaster',
    'TransformBroadcaster',
    'TransformListener',
]
__all__ += _tf2_py.__all__
__all__ += _buffer_interface.__all__
