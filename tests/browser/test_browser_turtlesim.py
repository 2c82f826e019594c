"""turtlesim's window in a real browser: a turtlesim_node started outside JupyterLab (as in
a terminal) is watched from a notebook cell; the page draws the turtle where its pose says
and its pen trail in the pen's colour, over turtlesim's background.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import browser_lab
import pytest
from browser_lab import Notebook, wait_until
from conftest import BIN, Proc

import robot_lab

pytestmark = [pytest.mark.browser, pytest.mark.timeout(600)]

CHROMIUM, sync_playwright = browser_lab.browser_or_skip()

# how many canvas pixels have this colour (within 12 per channel): the trail, the background
_COUNT = """([el, rgb]) => {
  const c = el.querySelector('canvas');
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (Math.abs(d[i] - rgb[0]) < 12 && Math.abs(d[i + 1] - rgb[1]) < 12 &&
        Math.abs(d[i + 2] - rgb[2]) < 12) n += 1;
  }
  return n;
}"""


def test_a_terminal_turtlesim_is_drawn_in_the_notebook(ros_domain: int, tmp_path: Path) -> None:
    root = tmp_path / 'lab'
    root.mkdir()
    (root / 'watch.ipynb').write_text(json.dumps({
        'cells': [{'cell_type': 'code', 'execution_count': None, 'id': 'watch', 'metadata': {},
                   'outputs': [], 'source': 'import robot_lab\nrobot_lab.turtlesim_view()'}],
        'metadata': {'kernelspec': {'name': 'robot_lab', 'display_name': 'robot_lab',
                                    'language': 'python'}},
        'nbformat': 4, 'nbformat_minor': 5}))
    env = browser_lab.lab_environment(tmp_path, 0)
    env['ROS_DOMAIN_ID'] = str(ros_domain)  # the kernel joins this module's domain
    sim = Proc([str(BIN / 'ros2'), 'run', 'turtlesim', 'turtlesim_node'],
               env=dict(os.environ))
    try:
        sim.wait_for(r'Spawning turtle \[turtle1\]', timeout=60)
        with browser_lab.jupyter_lab(root, env) as lab, sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM,
                                         args=browser_lab.CHROMIUM_ARGS)
            page = browser.new_page(viewport={'width': 1100, 'height': 900})
            book = Notebook(page, lab, 'watch.ipynb')
            book.run(0)
            view = book.output(0).locator('.rl-turtlesim').first
            view.wait_for(timeout=60_000)

            def turtles() -> list[list[float]]:
                return json.loads(view.get_attribute('data-turtles') or '[]')

            assert wait_until(lambda: [t[0] for t in turtles()] == ['turtle1'], 60), \
                book.text(0)
            assert view.get_attribute('data-background') == '69,86,255'
            start = turtles()[0]
            assert (round(start[1], 2), round(start[2], 2)) == (5.54, 5.54)
            assert page.evaluate(_COUNT, [view.element_handle(), [179, 184, 255]]) == 0
            robot_lab.publish('/turtle1/cmd_vel', 'geometry_msgs/msg/Twist',
                              '{linear: {x: 2.0}, angular: {z: 1.8}}')
            assert wait_until(lambda: abs(turtles()[0][1] - start[1]) > 0.5, 30), turtles()
            # the default pen (0xb3, 0xb8, 0xff) drew the arc on the page
            assert wait_until(lambda: page.evaluate(
                _COUNT, [view.element_handle(), [179, 184, 255]]) > 50, 30)
            robot_lab.param_set('/turtlesim', 'background_r', 150)
            assert wait_until(lambda: view.get_attribute('data-background') == '150,86,255',
                              30)
            view.screenshot(path=str(tmp_path / 'turtlesim_view.png'))
            assert not book.errors()
            browser.close()
    finally:
        sim.stop()
