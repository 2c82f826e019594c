"""The teleop pad in a real browser: a held button drives, letting go stops, and the
keyboard's own keys drive once the pad has focus, without JupyterLab acting on them.
The Twists are the ones a subscriber in this process receives.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import browser_lab
import pytest
from browser_lab import Notebook
from test_teleop import Inbox, parts

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

CHROMIUM, sync_playwright = browser_lab.browser_or_skip()

ZERO = (0.0,) * 6


def test_the_pad_drives_while_held_from_buttons_and_keys(ros_domain: int,
                                                         tmp_path: Path) -> None:
    from geometry_msgs.msg import Twist

    root = tmp_path / 'lab'
    root.mkdir()
    (root / 'drive.ipynb').write_text(json.dumps({
        'cells': [{'cell_type': 'code', 'execution_count': None, 'id': 'drive',
                   'metadata': {}, 'outputs': [],
                   'source': "import robot_lab\nrobot_lab.teleop('/cmd_vel', rate=20)"}],
        'metadata': {'kernelspec': {'name': 'robot_lab', 'display_name': 'robot_lab',
                                    'language': 'python'}},
        'nbformat': 4, 'nbformat_minor': 5}))
    env = browser_lab.lab_environment(tmp_path, 0)
    env['ROS_DOMAIN_ID'] = str(ros_domain)  # the kernel joins this module's domain
    inbox = Inbox('/cmd_vel', Twist)
    try:
        with browser_lab.jupyter_lab(root, env) as lab, sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM,
                                         args=browser_lab.CHROMIUM_ARGS)
            page = browser.new_page(viewport={'width': 1100, 'height': 900})
            book = Notebook(page, lab, 'drive.ipynb')
            book.run(0)
            pad = book.output(0).locator('.rl-teleop').first
            pad.wait_for(timeout=60_000)
            cells = book.count()

            def last_is(expected: tuple[float, ...]) -> Callable[[list[Any]], bool]:
                return lambda m: bool(m) and parts(m[-1]) == pytest.approx(expected)

            # Hold `i` with the mouse until the kernel's publisher has matched this
            # subscription and messages flow; several arrive while it stays down.
            forward = pad.locator('button[data-key="i"]')
            forward.hover()
            page.mouse.down()
            ahead = (0.5, 0.0, 0.0, 0.0, 0.0, 0.0)
            inbox.wait(lambda m: [parts(x) for x in m] == [ahead] * len(m) and len(m) >= 3,
                       'a held i drives at 0.5 m/s, 20 times a second', timeout=60)
            assert 'rl-held' in (forward.get_attribute('class') or '')
            page.mouse.up()
            inbox.wait(last_is(ZERO), 'letting go publishes zero')
            # the keyboard: focus the pad, hold l, then a speed key and i, then b (down)
            pad.focus()
            page.keyboard.down('l')
            inbox.wait(last_is((0, 0, 0, 0, 0, -1.0)), 'a held l key turns right')
            page.keyboard.up('l')
            inbox.wait(last_is(ZERO), 'releasing the key stops')
            page.keyboard.press('q')  # 10 % faster, both speeds
            page.keyboard.down('i')
            inbox.wait(last_is((0.55, 0, 0, 0, 0, 0)), 'q then i: 0.55 m/s')
            page.keyboard.up('i')
            inbox.wait(last_is(ZERO), 'and stops')
            page.keyboard.down('b')  # b is also JupyterLab's "insert a cell below"
            inbox.wait(last_is((0, 0, -0.55, 0, 0, 0)), 'b goes down')
            page.keyboard.up('b')
            inbox.wait(last_is(ZERO), 'and stops')
            assert book.count() == cells, 'JupyterLab took a key the pad had'
            assert not book.errors()
            pad.screenshot(path=str(tmp_path / 'teleop_pad.png'))
            browser.close()
    finally:
        inbox.close()
