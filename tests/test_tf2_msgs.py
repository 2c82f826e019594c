"""tf2_msgs, built by the kit from geometry2's definitions as example_interfaces is: the
tf2 tutorials and robot_state_publisher import it, and `ros2 interface` shows it."""

from __future__ import annotations

import sys
from pathlib import Path

from conftest import cli_ok

from robot_lab.pkg.kit_packages import kit_package_sources

SITE = Path(sys.prefix)


def test_tf2_msgs_is_built_from_upstreams_definitions() -> None:
    source = kit_package_sources('tf2_msgs')
    for rel in ('msg/TFMessage.msg', 'msg/TF2Error.msg', 'srv/FrameGraph.srv',
                'action/LookupTransform.action'):
        assert (SITE / 'share' / 'tf2_msgs' / rel).read_bytes() == (source / rel).read_bytes()
    assert 'BSD 3-Clause' in (source / 'LICENSE').read_text()


def test_tf2_msgs_imports_and_round_trips() -> None:
    from geometry_msgs.msg import TransformStamped
    from rclpy.serialization import deserialize_message, serialize_message
    from tf2_msgs.action import LookupTransform
    from tf2_msgs.msg import TF2Error, TFMessage
    from tf2_msgs.srv import FrameGraph

    sent = TFMessage(transforms=[TransformStamped(child_frame_id='turtle1')])
    sent.transforms[0].header.frame_id = 'world'
    back = deserialize_message(serialize_message(sent), TFMessage)
    assert back == sent
    assert TF2Error.EXTRAPOLATION_ERROR == 3 and TF2Error.TIMEOUT_ERROR == 5
    assert hasattr(FrameGraph.Response(), 'frame_yaml')
    assert LookupTransform.Goal().advanced is False


def test_ros2_interface_shows_tf2_msgs() -> None:
    assert cli_ok('interface', 'package', 'tf2_msgs').splitlines() == [
        'tf2_msgs/action/LookupTransform', 'tf2_msgs/msg/TF2Error',
        'tf2_msgs/msg/TFMessage', 'tf2_msgs/srv/FrameGraph']
    shown = cli_ok('interface', 'show', 'tf2_msgs/msg/TFMessage').splitlines()
    assert shown[0] == 'geometry_msgs/TransformStamped[] transforms'
