"""Every display of the 3D view, kernel side to pixels, without JupyterLab: a real
`SceneView` takes real messages (LaserScan, MarkerArray, Path, Odometry, PoseStamped, /tf
as its bytes) and what it would send the widget is recorded, then replayed into the
committed bundle in headless Chromium through a model like anywidget's. Each display's
colour must appear on the canvas, and the fixed-frame menu must set the model's trait."""

from __future__ import annotations

import io
import math
import struct
import time
from pathlib import Path
from typing import Any

import browser_lab
import pytest
from geometry_msgs.msg import Point, PoseStamped, TransformStamped
from nav_msgs.msg import Odometry
from nav_msgs.msg import Path as PathMsg
from rclpy.serialization import serialize_message
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

import robot_lab
from robot_lab.scene import displays
from robot_lab.scene.canvas import BUNDLE
from robot_lab.scene.view import SceneView

pytestmark = pytest.mark.browser
CHROMIUM, sync_playwright = browser_lab.browser_or_skip()
Image = pytest.importorskip('PIL.Image')

# what each display draws in, and how a pixel of it is told (r, g, b)
COLOURS = {
    'scan': lambda r, g, b: r > 200 and g > 200 and b < 80,  # yellow points
    'cube': lambda r, g, b: r > 120 and b > 120 and g < 60,  # magenta marker
    'path': lambda r, g, b: g > 200 and r < 80 and b < 80,  # RViz's path green
    'arrows': lambda r, g, b: r > 150 and g < 60 and b < 60,  # odometry and pose: red
    'stl': lambda r, g, b: g > 120 and b > 120 and r < 60,  # a cyan STL mesh marker
    'obj': lambda r, g, b: b > 120 and r < 50 and g < 50,  # a blue OBJ mesh marker
}
# a unit cube's corners and its 12 triangles (outward, counter-clockwise)
_CORNERS = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
_FACES = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4),
          (2, 6, 7), (2, 7, 3), (0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5)]


def _meshes(folder: Path) -> tuple[Path, Path]:
    """The cube as a binary STL and as an OBJ file."""
    stl = folder / 'cube.stl'
    triangles = b''.join(struct.pack('<12fH', 0, 0, 0, *_CORNERS[a], *_CORNERS[b],
                                     *_CORNERS[c], 0) for a, b, c in _FACES)
    stl.write_bytes(b'robot_lab test cube'.ljust(80, b' ') + struct.pack('<I', len(_FACES))
                    + triangles)
    obj = folder / 'cube.obj'
    obj.write_text(''.join(f'v {x} {y} {z}\n' for x, y, z in _CORNERS)
                   + ''.join(f'f {a + 1} {b + 1} {c + 1}\n' for a, b, c in _FACES))
    return stl, obj


def _tf(parent: str, child: str, x: float, yaw: float) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x = x
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def _messages(view: SceneView, stl: Path, obj: Path) -> None:
    """Real messages into the view's displays (as their subscriptions would take them)."""
    view._on_tf(serialize_message(TFMessage(transforms=[
        _tf('odom', 'base_link', 0.3, 0.0), _tf('base_link', 'laser', 0.1, 0.0)])))
    scan = LaserScan(angle_min=-math.pi, angle_increment=2 * math.pi / 360, range_min=0.1,
                     range_max=10.0, ranges=[1.2] * 360)
    scan.header.frame_id = 'laser'
    view.displays['laser_scan:/scan'].take(scan)
    cube = Marker(ns='w', id=1, type=Marker.CUBE, action=Marker.ADD)
    cube.header.frame_id = 'odom'
    cube.pose.position.y, cube.pose.orientation.w = -0.8, 1.0
    cube.scale.x = cube.scale.y = cube.scale.z = 0.4
    cube.color.r, cube.color.b, cube.color.a = 1.0, 1.0, 1.0
    meshes = []
    for ident, (path, rgb, y) in enumerate(((stl, (0.0, 1.0, 1.0), 0.9),
                                            (obj, (0.0, 0.0, 1.0), 1.5)), start=2):
        mesh = Marker(ns='w', id=ident, type=Marker.MESH_RESOURCE, action=Marker.ADD,
                      mesh_resource=f'file://{path}')
        mesh.header.frame_id = 'odom'
        mesh.pose.position.y, mesh.pose.position.x, mesh.pose.orientation.w = y, -0.6, 1.0
        mesh.scale.x = mesh.scale.y = mesh.scale.z = 0.4
        mesh.color.r, mesh.color.g, mesh.color.b = rgb
        mesh.color.a = 1.0
        meshes.append(mesh)
    view.displays['markers:/world'].take(MarkerArray(markers=[cube, *meshes]))
    path = PathMsg()
    path.header.frame_id = 'odom'
    for k in range(20):
        stamped = PoseStamped()
        stamped.pose.position = Point(x=-1.0 + 0.1 * k, y=0.6, z=0.05)
        path.poses.append(stamped)
    view.displays['path:/plan'].take(path)
    odom = Odometry()
    odom.header.frame_id = 'odom'
    odom.pose.pose.position.x, odom.pose.pose.orientation.w = -0.5, 1.0
    view.displays['odometry:/odom'].take(odom)
    goal = PoseStamped()
    goal.header.frame_id = 'base_link'
    goal.pose.position.y, goal.pose.orientation.w = 0.4, 1.0
    view.displays['pose:/goal_pose'].take(goal)


def _count(picture: Any, test: Any) -> int:
    data = picture.tobytes()
    return sum(1 for i in range(0, len(data), 3) if test(data[i], data[i + 1], data[i + 2]))


def test_each_display_draws_what_the_kernel_sent(ros_domain: int, tmp_path: Path) -> None:
    view = SceneView('odom', robot_description=None)
    recorder = browser_lab.SceneRecorder()
    try:
        view.remove('tf')  # its yellow-magenta arrows would count as the scan's yellow
        view.add('/scan', 'LaserScan', color=[1, 1, 0])
        view.add_display(displays.Markers('/world'))
        view.add('/plan', 'Path')
        view.add('/odom', 'Odometry')
        view.add('/goal_pose', 'Pose')
        view._scene_canvas = recorder  # type: ignore[assignment]
        view._on_msg(recorder, {'kind': 'ready'}, [])  # as a page that appeared asks
        _messages(view, *_meshes(tmp_path))
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:  # the view's thread sends at its next tick
            with recorder.lock:
                sent = {k for msg, _ in recorder.sent for k in msg.get('data', {})}
            if len(sent) == 5:
                break
            view._closed.wait(0.05)
        assert len(sent) == 5, sent
        with recorder.lock:
            replay = list(recorder.sent)
        # every view out of sight: the kernel keeps taking /tf but sends nothing, then
        # catches up when a view is seen again
        view._on_msg(recorder, {'kind': 'seen', 'view': 'v1', 'value': False}, [])
        view._on_tf(serialize_message(TFMessage(transforms=[_tf('odom', 'base_link', 0.9, 0.0)])))
        ticks, count = view.ticks, len(recorder.sent)
        while view.ticks < ticks + 3:
            view._closed.wait(0.02)  # the view's own ticks, counted
        assert len(recorder.sent) == count, 'a view out of sight was sent poses'
        view._on_msg(recorder, {'kind': 'seen', 'view': 'v1', 'value': True}, [])
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and len(recorder.sent) == count:
            view._closed.wait(0.02)
        assert recorder.sent[count][0]['poses']['base_link'][0] == 0.9
    finally:
        view.close()
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=browser_lab.CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={'width': 820, 'height': 600})
            browser_lab.show_scene(page, BUNDLE.read_text(), '')
            canvas = page.locator('.rl-scene canvas')
            empty = Image.open(io.BytesIO(canvas.screenshot())).convert('RGB')
            browser_lab.replay_scene(page, replay)
            assert browser_lab.wait_in_page(
                page, "() => document.querySelector('.rl-scene').dataset.drawnPoses === "
                "document.querySelector('.rl-scene').dataset.poses", None, 10)
            drawn = Image.open(io.BytesIO(canvas.screenshot())).convert('RGB')
            for name, test in COLOURS.items():
                before, after = _count(empty, test), _count(drawn, test)
                # the path is a line one pixel wide, about 200 pixels long
                assert before == 0 and after > 100, f'{name}: {before} pixels, then {after}'
            # orbit (drag), then zoom (wheel): the camera moves, the picture with it
            box = canvas.bounding_box()
            cx, cy = box['x'] + box['width'] / 2, box['y'] + box['height'] / 2
            for gesture in ('drag', 'wheel'):
                frames = int(page.evaluate("() => +document.querySelector('.rl-scene')"
                                           '.dataset.frames'))
                if gesture == 'drag':
                    page.mouse.move(cx, cy)
                    page.mouse.down()
                    page.mouse.move(cx + 120, cy + 30, steps=6)
                    page.mouse.up()
                else:
                    page.mouse.wheel(0, -400)
                assert browser_lab.wait_in_page(
                    page, "n => +document.querySelector('.rl-scene').dataset.frames > n",
                    frames, 10), gesture
                moved = Image.open(io.BytesIO(canvas.screenshot())).convert('RGB')
                changed = sum(1 for a, b in zip(drawn.tobytes(), moved.tobytes(), strict=True)
                              if abs(a - b) > 40)
                assert changed > 2000, f'{gesture}: {changed} channel values changed'
                drawn = moved
            # a robot description, then another: the second replaces the first
            urdf_dir = robot_lab.package_share('urdf_tutorial') / 'urdf'
            for number, name in enumerate(('01-myfirst.urdf', '03-origins.urdf')):
                robot = displays.RobotModel()
                robot.set_urdf((urdf_dir / name).read_text())
                robot._dirty = True
                sent = {'kind': 'update', 'data': {robot.id: robot.data(displays.Outbox(),
                                                                       full=False)}}
                if not number:
                    sent['add'] = [robot.spec()]
                browser_lab.replay_scene(page, [(sent, [])])
                assert browser_lab.wait_in_page(
                    page, "n => document.querySelector('.rl-scene').dataset.links == n",
                    str(len(robot.links)), 10), name
            menu = page.locator('.rl-scene select')
            assert menu.locator('option').all_text_contents() == ['base_link', 'laser', 'odom']
            menu.select_option('laser')
            assert page.evaluate('() => JSON.parse(window.saved.at(-1)).fixed_frame') == 'laser'
        finally:
            browser.close()
