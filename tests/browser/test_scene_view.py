"""The 3D view in a real browser: R2D2 (urdf_tutorial's 06-flexible) from a terminal's
robot_state_publisher, drawn by `robot_lab.scene_view()` in JupyterLab's headless Chromium.

What a student would see: WebGL, the robot's blue body where the model stands, its moving
links white at the origin with a status line saying why until /joint_states gives their
positions, the picture changing when a joint moves, and nothing fetched from anywhere but the
notebook server (meshes travel on the widget's channel).
"""

from __future__ import annotations

import io
import json
import os
from pathlib import Path
from typing import Any

import browser_lab
import pytest
import yaml
from browser_lab import Notebook, wait_in_page
from conftest import BIN, Proc

import robot_lab

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

CHROMIUM, sync_playwright = browser_lab.browser_or_skip()
Image = pytest.importorskip('PIL.Image')

URDF = (Path(robot_lab.__file__).parent / 'data' / 'ament_packages' / 'urdf_tutorial' / 'urdf'
        / '06-flexible.urdf')
VIEW = '.rl-scene'


def _notebook(root: Path) -> None:
    (root / 'view.ipynb').write_text(json.dumps({
        'cells': [{'cell_type': 'code', 'execution_count': None, 'id': cell, 'metadata': {},
                   'outputs': [], 'source': source} for cell, source in (
                       ('view', "import robot_lab\nview = robot_lab.scene_view('base_link')\n"
                                'view'),
                       ('sliders', 'robot_lab.joint_sliders()'),
                       ('hide', "print(view.hidden_frames)\nview.hide_frames(['head', 'box'])"))],
        'metadata': {'kernelspec': {'name': 'robot_lab', 'display_name': 'robot_lab',
                                    'language': 'python'}},
        'nbformat': 4, 'nbformat_minor': 5}))


def _picture(view: Any) -> Any:
    return Image.open(io.BytesIO(view.locator('canvas').screenshot())).convert('RGB')


def _pixels(picture: Any) -> list[tuple[int, int, int]]:
    data = picture.tobytes()
    return list(zip(data[0::3], data[1::3], data[2::3], strict=True))


def _blue(picture: Any, box: tuple[int, int, int, int] | None = None) -> int:
    """Pixels of R2D2's blue body (rgba 0 0 0.8, lit): blue, little red or green."""
    part = picture.crop(box) if box else picture
    return sum(1 for r, g, b in _pixels(part) if b > 90 and r < 70 and g < 70 and b > 2 * r)


# the head's yaw in base_link is `v` (head_swivel turns about z), and that is drawn
_HEAD_AT = """([el, v]) => {
  const m = el.rlPoses.get('head');
  return !!m && Math.abs(Math.atan2(m.elements[1], m.elements[0]) - v) < 0.01
    && el.dataset.drawnPoses === el.dataset.poses;
}"""
# the page has drawn every pose update it got, and more than `n` of them
_SHOWN = '([el, n]) => +el.dataset.poses > n && el.dataset.drawnPoses === el.dataset.poses'


def test_r2d2_is_drawn_and_moves_with_its_joints(ros_domain: int, tmp_path: Path) -> None:
    root = tmp_path / 'lab'
    root.mkdir()
    _notebook(root)
    params = tmp_path / 'rsp.yaml'
    params.write_text(yaml.safe_dump({'robot_state_publisher': {'ros__parameters': {
        'robot_description': URDF.read_text()}}}))
    env = browser_lab.lab_environment(tmp_path, 0)
    env['ROS_DOMAIN_ID'] = str(ros_domain)
    rsp = Proc([str(BIN / 'ros2'), 'run', 'robot_state_publisher', 'robot_state_publisher',
                '--ros-args', '--params-file', str(params)], env=dict(os.environ))
    requests: list[str] = []
    try:
        rsp.wait_for('Robot initialized', timeout=60)
        with browser_lab.jupyter_lab(root, env) as lab, sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM,
                                         args=browser_lab.CHROMIUM_ARGS)
            page = browser.new_page(viewport={'width': 1100, 'height': 900})
            page.on('request', lambda request: requests.append(request.url))
            page.on('websocket', lambda socket: requests.append(socket.url))
            book = Notebook(page, lab, 'view.ipynb')
            book.run(0)
            view = book.output(0).locator(VIEW).first
            view.wait_for(timeout=60_000)
            handle = view.element_handle()

            # No /joint_states yet: the fixed links are placed, the moving ones are white
            # at the origin, and the status line says why.
            assert wait_in_page(page, """el => el.dataset.robot === 'drawn'
                && el.querySelector('.rl-status').textContent.includes('No transform from')""",
                                handle, 60), (view.get_attribute('data-robot'), book.text(0))
            assert str(view.get_attribute('data-webgl')).split()[0] in {'webgl', 'webgl2'}
            assert view.get_attribute('data-links') == '16'
            status = str(view.locator('.rl-status').text_content())
            assert '[head]' in status and 'drawn white at the origin' in status, status
            assert 'joint_state_publisher' in status, status

            book.run(1)  # the sliders: /joint_states at 10 Hz, every joint at 0
            sliders = book.output(1)
            sliders.locator('.widget-slider').first.wait_for(timeout=30_000)
            view.scroll_into_view_if_needed()  # a view out of sight draws nothing
            assert wait_in_page(page, """el => !el.querySelector('.rl-status')
                .textContent.includes('No transform')""", handle, 30), \
                view.locator('.rl-status').text_content()
            assert wait_in_page(page, _SHOWN, [handle, 0], 10)
            box = [round(float(v)) for v in str(view.get_attribute('data-robot-box')).split(',')]
            before = _picture(view)
            inside = _blue(before, (box[0], box[1], box[2], box[3]))
            assert inside > 1500, f'{inside} blue pixels where the robot stands, box {box}'
            assert _blue(before) - inside < 0.05 * inside, 'blue drawn away from the robot'

            # drag head_swivel's slider from 0 to near +π, as a student would
            poses = int(view.get_attribute('data-poses') or 0)
            slider = sliders.locator('.widget-slider', has_text='head_swivel')
            slider.scroll_into_view_if_needed()
            knob = slider.locator('.noUi-handle').bounding_box()
            track = slider.locator('.noUi-target').bounding_box()
            y = knob['y'] + knob['height'] / 2
            page.mouse.move(knob['x'] + knob['width'] / 2, y)
            page.mouse.down()
            page.mouse.move(track['x'] + 0.92 * track['width'], y, steps=8)
            page.mouse.up()
            readout = slider.locator('.widget-readout')
            final = float(readout.text_content() or 0)
            assert final > 2.0, readout.text_content()
            view.scroll_into_view_if_needed()
            # the drag sent several positions: wait for the head at the last one, drawn
            assert wait_in_page(page, _HEAD_AT, [handle, final], 30), page.evaluate(
                "el => el.rlPoses.get('head')?.elements", handle)
            assert int(view.get_attribute('data-poses') or 0) > poses
            after = _picture(view)
            moved = sum(1 for a, b in zip(_pixels(before), _pixels(after), strict=True)
                        if sum(abs(x - y) for x, y in zip(a, b, strict=True)) > 60)
            assert moved > 500, f'only {moved} pixels changed when the head turned'
            # each TF frame can be hidden, as in RViz's TF display
            shown = int(view.get_attribute('data-tf-shown') or 0)
            view.locator('details summary').click()
            view.locator('details label', has_text='head').first.locator('input').uncheck()
            assert wait_in_page(page, '([el, n]) => +el.dataset.tfShown === n - 1',
                                [handle, shown], 10)
            book.run(2)  # the kernel heard the click; Python hides one more
            assert "['head']" in book.text(2), book.text(2)
            assert wait_in_page(page, '([el, n]) => +el.dataset.tfShown === n - 2',
                                [handle, shown], 10)
            # another fixed frame, picked in the view's menu: the kernel re-resolves every pose
            view.scroll_into_view_if_needed()  # running cell 2 scrolled it away
            view.locator('select').select_option('right_leg')
            assert wait_in_page(page, "el => el.dataset.fixed === 'right_leg'", handle, 10)
            assert not book.errors(), book.errors()
            browser.close()
    finally:
        rsp.stop()
    base = 'http://127.0.0.1:'
    away = [url for url in requests
            if not url.startswith((base, 'ws://127.0.0.1:', 'blob:', 'data:'))]
    assert requests and not away, f'requests off loopback: {away[:5]}'
