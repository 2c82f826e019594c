"""A running simulation in the 3D view, to pixels: `robot_lab.sim_view('room.sdf')`.

The simulator runs the room with the sample diff-drive robot, spawned, bridged and described
as a Gazebo Harmonic lab does it (gz_sim.launch.py, robot_state_publisher, `create`,
parameter_bridge for /scan, the model's tf as /tf, /joint_states). A real `SceneView` takes
what ROS carries; what it would send the widget is recorded, then replayed into the committed
bundle in headless Chromium (as test_scene_view_displays does, without JupyterLab). The
first picture, from the camera sim_view chose, must show all four walls and the robot; then
`look_at` moves the camera near, and the walls, the robot and the scan points on the walls
must be where that camera's projection puts them. Both screenshots are saved.
"""

from __future__ import annotations

import io
import math
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import browser_lab
import pytest
from conftest import Proc
from rosutil import diffbot_launch

import robot_lab
from robot_lab.scene.canvas import BUNDLE

pytestmark = pytest.mark.browser
CHROMIUM, sync_playwright = browser_lab.browser_or_skip()
Image = pytest.importorskip('PIL.Image')

LAUNCH = """\
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch_ros.actions import Node


def generate_launch_description():
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, 'diffbot.urdf')) as infp:
        robot_desc = infp.read()
    gz_sim = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(os.path.join(
            get_package_share_directory('ros_gz_sim'), 'launch', 'gz_sim.launch.py')),
        launch_arguments={'gz_args': '-r room.sdf'}.items())
    return LaunchDescription([
        gz_sim,
        Node(package='ros_gz_bridge', executable='parameter_bridge',
             parameters=[{'config_file': os.path.join(here, 'bridge.yaml')}]),
        Node(package='robot_state_publisher', executable='robot_state_publisher',
             parameters=[{'use_sim_time': True}, {'robot_description': robot_desc}]),
        Node(package='ros_gz_sim', executable='create',
             arguments=['-topic', 'robot_description', '-name', 'diffbot', '-z', '0.051']),
    ])
"""
BRIDGE_YAML = """\
- ros_topic_name: "clock"
  gz_topic_name: "clock"
  ros_type_name: "rosgraph_msgs/msg/Clock"
  gz_type_name: "gz.msgs.Clock"
  direction: GZ_TO_ROS
- ros_topic_name: "scan"
  gz_topic_name: "scan"
  ros_type_name: "sensor_msgs/msg/LaserScan"
  gz_type_name: "gz.msgs.LaserScan"
  direction: GZ_TO_ROS
- ros_topic_name: "/tf"
  gz_topic_name: "/model/diffbot/tf"
  ros_type_name: "tf2_msgs/msg/TFMessage"
  gz_type_name: "gz.msgs.Pose_V"
  direction: GZ_TO_ROS
- ros_topic_name: "joint_states"
  gz_topic_name: "joint_states"
  ros_type_name: "sensor_msgs/msg/JointState"
  gz_type_name: "gz.msgs.Model"
  direction: GZ_TO_ROS
"""
WIDTH, HEIGHT = 800, 400
# the bundle's first camera (js/scene_view/src/scene.js): eye, target, vertical field of view
EYE, TARGET, FOV = (1.8, 1.4, 1.2), (0.0, 0.0, 0.3), 50.0
INNER = 2.0  # the room's walls' inner faces, from its centre (room.sdf)
OUTER, TOP = 2.1, 0.5  # their outer faces and their height
Point = tuple[float, float, float]


def _is_scan(r: int, g: int, b: int) -> bool:  # the LaserScan display's red points
    return r > 180 and g < 80 and b < 80


def _is_wall(r: int, g: int, b: int) -> bool:  # world_markers' light grey, lit
    return min(r, g, b) > 110 and max(r, g, b) - min(r, g, b) < 40


def _pixels(picture: Any) -> Iterator[tuple[int, int, int]]:
    data = picture.tobytes()
    return ((data[i], data[i + 1], data[i + 2]) for i in range(0, len(data), 3))


def _is_robot(r: int, g: int, b: int) -> bool:  # a URDF without materials: white, lit
    return min(r, g, b) > 190


def _project(point: Point, eye: Point = EYE,
             target: Point = TARGET) -> tuple[float, float] | None:
    """Where three.js draws a point of the fixed frame: pixel x, y (None: behind the eye)."""
    def sub(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, ...]:
        return tuple(p - q for p, q in zip(a, b, strict=True))

    def cross(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, ...]:
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    def unit(a: tuple[float, ...]) -> tuple[float, ...]:
        n = math.sqrt(sum(v * v for v in a))
        return tuple(v / n for v in a)

    def dot(a: tuple[float, ...], b: tuple[float, ...]) -> float:
        return sum(p * q for p, q in zip(a, b, strict=True))

    forward = unit(sub(target, eye))
    right = unit(cross(forward, (0.0, 0.0, 1.0)))
    up = cross(right, forward)
    d = sub(point, eye)
    depth = dot(d, forward)
    if depth <= 0.05:
        return None
    f = (HEIGHT / 2) / math.tan(math.radians(FOV) / 2)
    return WIDTH / 2 + f * dot(d, right) / depth, HEIGHT / 2 - f * dot(d, up) / depth


def _near(picture: Any, xy: tuple[float, float], test: Any, radius: int) -> bool:
    x0, y0 = round(xy[0]), round(xy[1])
    return any(test(*picture.getpixel((x, y)))
               for x in range(max(0, x0 - radius), min(WIDTH, x0 + radius + 1))
               for y in range(max(0, y0 - radius), min(HEIGHT, y0 + radius + 1)))


def _robot_corners(lz: float, eye: Point, target: Point) -> list[float]:
    """The screen box of the robot's chassis (0.4 m square, at the odom origin)."""
    corners = [_project((x, y, z), eye, target) for x in (-0.2, 0.2) for y in (-0.2, 0.2)
               for z in (lz - 0.2, lz + 0.02)]
    return [min(c[0] for c in corners if c), min(c[1] for c in corners if c),
            max(c[0] for c in corners if c), max(c[1] for c in corners if c)]


def _the_whole_room_in_sight(drawn: Any, empty: Any, camera: tuple[Point, Point],
                             robot_box: list[float], lz: float) -> None:
    """sim_view's first picture: every corner of the room on screen, each of the four
    walls' tops drawn in wall grey along its length, the robot where the camera puts it."""
    eye, target = camera
    for x in (-OUTER, OUTER):
        for y in (-OUTER, OUTER):
            for z in (0.0, TOP):
                xy = _project((x, y, z), eye, target)
                assert xy is not None and 0 <= xy[0] < WIDTH and 0 <= xy[1] < HEIGHT, (x, y, z)
    middle = (INNER + OUTER) / 2
    for name, (cx, cy, ax, ay) in {'north': (middle, 0, 0, 1), 'south': (-middle, 0, 0, 1),
                                   'west': (0, middle, 1, 0), 'east': (0, -middle, 1, 0)}.items():
        for along in (-1.5, -0.5, 0.5, 1.5):
            xy = _project((cx + ax * along, cy + ay * along, TOP - 0.01), eye, target)
            assert xy is not None
            assert _near(drawn, xy, _is_wall, 1), (name, along, xy)
            assert not _near(empty, xy, _is_wall, 1), (name, along, xy)
    mine = _robot_corners(lz, eye, target)
    assert all(abs(a - b) < 10 for a, b in zip(mine, robot_box, strict=True)), (mine, robot_box)


@pytest.fixture
def simulation(ros_domain: int, tmp_path: Path) -> Iterator[Proc]:
    with diffbot_launch(tmp_path, LAUNCH, BRIDGE_YAML) as process:
        yield process


def test_the_world_the_robot_and_its_scan_in_the_3d_view(simulation: Proc,
                                                           tmp_path: Path) -> None:
    view = robot_lab.sim_view('room.sdf')
    recorder = browser_lab.SceneRecorder('odom')
    first = view.camera  # sim_view's, from the world's extent
    assert first is not None
    try:
        assert list(view.displays) == ['grid', 'robot_model:/robot_description', 'tf',
                                       'world', 'laser_scan:/scan']
        view.remove('tf')  # its axes would hide the robot's own pixels
        view._scene_canvas = recorder  # type: ignore[assignment]
        view._on_msg(recorder, {'kind': 'ready'}, [])  # as a page that appeared asks
        wanted = {'robot_model:/robot_description', 'world', 'laser_scan:/scan'}
        deadline = time.monotonic() + 40
        while time.monotonic() < deadline:  # the simulation starts, then the view's ticks
            with recorder.lock:
                sent = {k for msg, _ in recorder.sent for k in msg.get('data', {})}
                posed = {k for msg, _ in recorder.sent for k in msg.get('poses') or {}}
            if wanted <= sent and {'base_link', 'laser_frame', 'left_wheel'} <= posed:
                break
            view._closed.wait(0.05)
        assert wanted <= sent, (sent, view.status, simulation.output[-3000:])
        assert {'base_link', 'laser_frame', 'left_wheel'} <= posed, (posed, view.status)
        laser = view.frames()['laser_frame']
        assert laser is not None
        with recorder.lock:
            replay = list(recorder.sent)
    finally:
        view.close()
    lx, ly, lz = laser[:3]  # the lidar in odom: the robot rests at the room's centre
    assert abs(lx) < 0.05 and abs(ly) < 0.05 and 0.1 < lz < 0.3, laser
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=browser_lab.CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={'width': 820, 'height': 600})
            browser_lab.show_scene(page, BUNDLE.read_text(), 'odom',
                                   {'camera': [*first[0], *first[1]]})
            canvas = page.locator('.rl-scene canvas')
            empty = Image.open(io.BytesIO(canvas.screenshot())).convert('RGB')
            browser_lab.replay_scene(page, replay)
            assert browser_lab.wait_in_page(
                page, "() => { const r = document.querySelector('.rl-scene'); return "
                "r.dataset.robot === 'drawn' && r.dataset.drawnPoses === r.dataset.poses; }",
                None, 15), page.evaluate("() => ({...document.querySelector('.rl-scene').dataset})")
            far_box = [float(v) for v in page.evaluate(
                "() => document.querySelector('.rl-scene').dataset.robotBox").split(',')]
            shot = canvas.screenshot()
            (tmp_path / 'sim_view_first.png').write_bytes(shot)
            whole = Image.open(io.BytesIO(shot)).convert('RGB')
            # view.look_at, as the kernel's trait change reaches the page
            view.look_at(EYE, TARGET)
            assert view.camera == (EYE, TARGET)
            frames = int(page.evaluate("() => document.querySelector('.rl-scene').dataset.frames"))
            page.evaluate("c => window.setTrait('camera', c)", recorder.camera)
            assert browser_lab.wait_in_page(
                page, "n => +document.querySelector('.rl-scene').dataset.frames > n", frames, 15)
            robot_box = [float(v) for v in page.evaluate(
                "() => document.querySelector('.rl-scene').dataset.robotBox").split(',')]
            shot = canvas.screenshot()
            (tmp_path / 'sim_view.png').write_bytes(shot)
            drawn = Image.open(io.BytesIO(shot)).convert('RGB')
            assert (drawn.width, drawn.height) == (WIDTH, HEIGHT)
        finally:
            browser.close()
    _the_whole_room_in_sight(whole, empty, first, far_box, lz)
    # walls: the south (x = -2) and east (y = -2) walls' inner faces, from their foot up to
    # above the scan's line, and the floor in front of them (off the grid's lines)
    for k in range(-12, 13, 3):
        along = k / 10 + 0.05
        for face, floor in (((-INNER + 0.02, along), (-INNER + 0.2, along)),
                            ((along, -INNER + 0.02), (along, -INNER + 0.2))):
            for z in (0.03, 0.4):
                xy = _project((*face, z))
                assert xy is not None and 0 <= xy[0] < WIDTH and 0 <= xy[1] < HEIGHT, face
                at = (round(xy[0]), round(xy[1]))
                assert _is_wall(*drawn.getpixel(at)), (face, z, at, drawn.getpixel(at))
                assert not _is_wall(*empty.getpixel(at)), (face, z, at)
            xy = _project((*floor, 0.0))
            assert xy is not None
            at = (round(xy[0]), round(xy[1]))
            assert not _is_wall(*drawn.getpixel(at)), (floor, at, drawn.getpixel(at))
    # the robot: its chassis box at the odom origin, where the page says it drew the robot
    mine = _robot_corners(lz, EYE, TARGET)
    assert all(abs(a - b) < 25 for a, b in zip(mine, robot_box, strict=True)), (mine, robot_box)
    x0, y0, x1, y1 = (round(v) for v in robot_box)
    inside = [(x, y) for x in range(x0, x1) for y in range(y0, y1)]
    robot_pixels = sum(1 for xy in inside if _is_robot(*drawn.getpixel(xy)))
    assert robot_pixels > 0.3 * len(inside) > 300, (robot_pixels, len(inside))
    everywhere = sum(1 for p in _pixels(drawn) if _is_robot(*p))
    assert everywhere - robot_pixels < 0.05 * robot_pixels, 'robot-white pixels elsewhere'
    top = _project((0.0, 0.0, lz - 0.05))  # the chassis' top face, at the odom origin
    assert top is not None and _near(drawn, top, _is_robot, 2), top
    assert not any(_is_robot(*p) for p in _pixels(empty))
    # the scan: a red point where each beam meets the south or east wall, on screen
    hits = []
    for k in range(360):
        angle = -math.pi + k * 2 * math.pi / 360
        c, s = math.cos(angle), math.sin(angle)
        reach = INNER / max(abs(c), abs(s))
        if c < -0.5 or s < -0.5:  # on the south or east wall, in front of the camera
            xy = _project((lx + reach * c, ly + reach * s, lz))
            if xy is not None and 5 <= xy[0] < WIDTH - 5 and 5 <= xy[1] < HEIGHT - 5:
                hits.append(xy)
    assert len(hits) > 50, len(hits)
    found = sum(_near(drawn, xy, _is_scan, 3) for xy in hits)
    assert found >= 0.9 * len(hits), f'{found} of {len(hits)} beams drawn on the walls'
    assert not any(_is_scan(*p) for p in _pixels(empty))
