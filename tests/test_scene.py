"""The 3D view's kernel side: the TF bytes it reads, the poses it resolves, the meshes it
sends, what its displays keep, and a view taking a real robot description and /tf_static.
(The browser side is tests/browser/test_scene_view.py.)"""

from __future__ import annotations

import math
import random
import time
from typing import Any

import pytest
from geometry_msgs.msg import Point, TransformStamped
from rclpy.serialization import serialize_message
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker

import robot_lab
from robot_lab.errors import GraphError
from robot_lab.scene.camera import FOV, extent, overview
from robot_lab.scene.displays import Markers, Outbox, RobotModel
from robot_lab.scene.frames import FrameTree, compose, inverse, parse_tf_message
from robot_lab.scene.meshes import MeshFiles

URDF_DIR = robot_lab.package_share('urdf_tutorial') / 'urdf'


def _yaw(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


def _close(a: Any, b: Any) -> bool:
    return all(abs(x - y) < 1e-12 for x, y in zip(a, b, strict=True))


@pytest.mark.no_ros
def test_the_tf_bytes_read_as_rclpy_reads_them() -> None:
    rng = random.Random(7)
    msg = TFMessage()
    for i in range(23):
        t = TransformStamped()
        t.header.stamp.sec, t.header.stamp.nanosec = i, 999
        t.header.frame_id = 'f' * (i % 5) + f'parent{i}'  # every string padding
        t.child_frame_id = f'c{i}' + 'é' * (i % 3)
        (t.transform.translation.x, t.transform.translation.y,
         t.transform.translation.z) = (rng.uniform(-9, 9) for _ in range(3))
        (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
         t.transform.rotation.w) = (rng.uniform(-1, 1) for _ in range(4))
        msg.transforms.append(t)
    expected = [(t.header.frame_id, t.child_frame_id, (
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z,
        t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
        t.transform.rotation.w)) for t in msg.transforms]
    raw = serialize_message(msg)
    assert parse_tf_message(raw) == expected
    assert parse_tf_message(serialize_message(TFMessage())) == []
    with pytest.raises(ValueError):
        parse_tf_message(raw[:-8])
    with pytest.raises(ValueError):
        parse_tf_message(b'\x00\x03' + raw[2:])  # XCDR2: not read here, rclpy reads it


@pytest.mark.no_ros
def test_frames_resolve_in_the_fixed_frame_through_their_tree() -> None:
    tree = FrameTree()
    assert tree.put('odom', 'base_link', (1.0, 0.0, 0.0, *_yaw(math.pi / 2)))
    assert tree.put('base_link', 'laser', (0.5, 0.0, 0.2, *_yaw(0.0)))
    assert not tree.put('base_link', 'laser', (0.5, 0.0, 0.2, *_yaw(0.0)))  # nothing new
    tree.put('map', 'other', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
    poses = tree.resolve('odom')
    # the laser is 0.5 m ahead of a base turned 90° left: (1, 0.5) in odom
    assert _close(poses['laser'], (1.0, 0.5, 0.2, *_yaw(math.pi / 2)))
    assert poses['other'] is None and poses['map'] is None
    from_laser = tree.resolve('laser')
    assert _close(from_laser['odom'], inverse(poses['laser']))  # type: ignore[arg-type]
    assert _close(compose(poses['laser'], from_laser['base_link']),  # type: ignore[arg-type]
                  poses['base_link'])
    assert tree.why_not('other', 'odom') == ('[other] and [odom] are not part of the same '
                                             'tree (their roots are [map] and [odom])')
    assert tree.why_not('wheel', 'odom') == 'frame [wheel] does not exist'
    assert not tree.put('odom', 'bad', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert 'zero quaternion' in tree.why_not('bad', 'odom')
    assert not tree.put('odom', 'odom', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
    tree.put('a', 'b', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
    tree.put('b', 'a', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
    assert tree.resolve('odom')['a'] is None
    assert 'loop' in tree.why_not('a', 'odom')


@pytest.mark.no_ros
def test_meshes_are_read_through_the_ament_index_with_their_textures() -> None:
    model = RobotModel()
    model.set_urdf((URDF_DIR / '05-visual.urdf').read_text())
    uris = model.mesh_uris
    assert uris == ['package://urdf_tutorial/meshes/l_finger.dae',
                    'package://urdf_tutorial/meshes/l_finger_tip.dae']
    files = MeshFiles()
    buffers: list[bytes] = []
    packed: Any = files.pack([*uris, 'package://no_such_pkg/m.stl',
                              f'file://{URDF_DIR}/missing.stl'], buffers)
    first = packed[uris[0]]
    assert buffers[first['index']].startswith(b'<?xml')
    assert buffers[first['textures']['l_finger_color.png']].startswith(b'\x89PNG')
    assert "Package 'no_such_pkg' not found" in packed['package://no_such_pkg/m.stl']['error']
    assert 'No such file' in packed[f'file://{URDF_DIR}/missing.stl']['error']
    assert files.pack(uris, buffers) == {}  # sent once until the browser asks for all again


@pytest.mark.no_ros
def test_markers_keep_what_is_alive_and_send_what_changed() -> None:
    markers = Markers('/m')

    def marker(ns: str, ident: int, action: int = 0, life: float = 0.0) -> Marker:
        m = Marker(ns=ns, id=ident, action=action, type=Marker.CUBE)
        m.header.frame_id = 'map'
        m.lifetime.sec, m.lifetime.nanosec = int(life), int(life % 1 * 1e9)
        return m

    for m in (marker('a', 1), marker('a', 2), marker('b', 1, life=0.05)):
        markers.take(m)
    sent: Any = markers.data(Outbox(), full=False)
    assert [op['key'] for op in sent['ops']] == ['a/1', 'a/2', 'b/1']
    assert markers.data(Outbox(), full=False) is None
    markers.take(marker('a', 2, action=Marker.DELETE))
    markers.take(marker('a', 0, action=Marker.DELETEALL))
    assert [op['action'] for op in markers.data(Outbox(), full=False)['ops']] == [2, 3]  # type: ignore[index]
    assert list(markers.items) == ['b/1']
    markers.expiry['b/1'] = time.monotonic() - 1  # its lifetime is over
    assert markers.data(Outbox(), full=False) == {'ops': [{'action': 2, 'key': 'b/1'}]}
    assert markers.data(Outbox(), full=True) == {'ops': [{'action': 3, 'ns': ''}]}


@pytest.mark.no_ros
def test_the_first_camera_sees_every_corner_of_a_world() -> None:
    wall = Marker(ns='w', id=1, type=Marker.CUBE)  # 4.2 m long, turned to run along x
    wall.pose.position.y, wall.pose.position.z = 2.05, 0.25
    wall.pose.orientation.z, wall.pose.orientation.w = math.sin(math.pi / 4), math.cos(math.pi / 4)
    wall.scale.x, wall.scale.y, wall.scale.z = 0.1, 4.2, 0.5
    line = Marker(ns='w', id=2, type=Marker.LINE_STRIP)  # its points, not its scale
    line.pose.position.x, line.pose.orientation.w = 1.0, 1.0
    line.points = [Point(x=-3.0, y=-1.0), Point(x=0.5, y=0.0, z=1.0)]
    markers = Markers(None, name='world')
    assert extent(markers) is None
    markers.set_markers([wall, line])
    low, high = extent(markers) or ((0.0,) * 3, (0.0,) * 3)
    assert _close(low, (-2.1, -1.0, 0.0)) and _close(high, (2.1, 2.1, 1.0)), (low, high)
    eye, target = overview(low, high)
    assert _close(target, (0.0, 0.55, 0.5))
    assert eye[0] < target[0] and eye[2] > target[2] and eye[1] == target[1]  # above, behind
    forward = [t - e for t, e in zip(target, eye, strict=True)]
    norm = math.sqrt(sum(f * f for f in forward))
    forward = [f / norm for f in forward]
    up = [-forward[2] * forward[0], -forward[2] * forward[1], forward[0] ** 2 + forward[1] ** 2]
    up = [u / math.sqrt(sum(v * v for v in up)) for u in up]
    slope = math.tan(math.radians(FOV) / 2)
    worst = 0.0
    for corner in [(x, y, z) for x in (low[0], high[0]) for y in (low[1], high[1])
                   for z in (low[2], high[2])]:
        d = [c - e for c, e in zip(corner, eye, strict=True)]
        depth = sum(a * b for a, b in zip(d, forward, strict=True))
        tall = abs(sum(a * b for a, b in zip(d, up, strict=True))) / depth / slope
        wide = abs(d[1]) / depth / slope / 1.25  # forward has no y: sideways is y
        worst = max(worst, tall, wide)
    assert 0.85 < worst < 1.0, worst  # all in the picture, none far inside its edges


@pytest.mark.no_ros
def test_a_robot_model_says_which_links_have_no_transform_and_why() -> None:
    robot = RobotModel()
    robot.set_urdf((URDF_DIR / '06-flexible.urdf').read_text())
    robot.count = 1
    assert robot.root == 'base_link' and len(robot.links) == 16
    tree = FrameTree()
    tree.put('base_link', 'right_leg', (0.0, -0.22, 0.25, 0.0, 0.0, 0.0, 1.0))
    tree.put('elsewhere', 'head', (0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 1.0))
    lines = robot.status(tree.resolve('base_link'), tree, 'base_link')
    assert lines[0].startswith('No transform from [right_base], [right_front_wheel]')
    assert 'and 7 more to [base_link]: nothing publishes these frames on /tf' in lines[0]
    assert 'joint_state_publisher' in lines[0] and 'drawn white at the origin' in lines[0]
    assert lines[1] == ('No transform from [head] to [base_link]: [head] and [base_link] are '
                        'not part of the same tree (their roots are [elsewhere] and '
                        '[base_link]); drawn white at the origin')
    robot.set_urdf('<robot name="r">\n<link name="a">\n</robot>')
    assert robot.status({}, tree, 'base_link') == [
        'RobotModel: the URDF on /robot_description does not parse (mismatched tag: line 3, '
        'column 2); '
        'fix: check it with `check_urdf` or `xacro` first']


def test_a_view_takes_the_robot_and_its_static_frames(ros_domain: int) -> None:
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from std_msgs.msg import String

    session = robot_lab.session()
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    description = session.node.create_publisher(String, '/robot_description', latched)
    static = session.node.create_publisher(TFMessage, '/tf_static', latched)
    description.publish(String(data=(URDF_DIR / '02-multipleshapes.urdf').read_text()))
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = 'base_link', 'right_leg'
    t.transform.translation.y, t.transform.rotation.w = -0.22, 1.0
    static.publish(TFMessage(transforms=[t]))
    view = robot_lab.scene_view(headless_seconds=10)  # its fixed frame: the robot's root
    try:
        deadline = time.monotonic() + 20
        while not view._picture_ready() and time.monotonic() < deadline:
            time.sleep(0.05)  # polling what the view's own thread has taken
        assert view.fixed_frame == 'base_link'
        assert view.frames() == {'base_link': (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
                                 'right_leg': (0.0, -0.22, 0.0, 0.0, 0.0, 0.0, 1.0)}
        assert view.status == ['2 frames in [base_link]']
        view.fixed_frame = 'right_leg'
        assert view.frames()['base_link'] == (0.0, 0.22, 0.0, -0.0, -0.0, -0.0, 1.0)
        assert view.render_png().startswith(b'\x89PNG')
        with pytest.raises(GraphError, match=r"cannot tell which display draws /nobody: "
                           r"nothing publishes it yet.*view.add\('/nobody', 'LaserScan'\)"):
            view.add('/nobody')
        with pytest.raises(GraphError, match=r"no display named 'PointCloud2'"):
            view.add('/cloud', 'PointCloud2')
        wall = Marker(ns='walls', id=3, type=Marker.CUBE)
        wall.header.frame_id = 'base_link'
        shown = view.show_markers('world', [wall])
        assert view.displays['world'] is shown and list(shown.items) == ['walls/3']
        assert shown.status(view.frames(), view.tree, 'right_leg') == []
        assert view.camera is None  # the bundle's own first camera
        view.look_at(eye=(-4, 0, 3), target=(0.0, 0.5, 0.0))
        assert view.camera == ((-4.0, 0.0, 3.0), (0.0, 0.5, 0.0))
        assert view.canvas.camera == [-4.0, 0.0, 3.0, 0.0, 0.5, 0.0]  # the page's trait
        view.look_at((1, 1, 1), (0, 0, 0))
        assert view.canvas.camera == [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
        for eye, target in (((1, 1, 1), (1, 1, 1)), ((1, 1), (0, 0, 0)),
                            ((1, 1, 'x'), (0, 0, 0)), ((math.nan, 0, 0), (0, 0, 0))):
            with pytest.raises(GraphError, match=r'not a camera.*two different points'):
                view.look_at(eye, target)  # type: ignore[arg-type]
        assert view.camera == ((1.0, 1.0, 1.0), (0.0, 0.0, 0.0))
    finally:
        view.close()
        session.node.destroy_publisher(description)
        session.node.destroy_publisher(static)
