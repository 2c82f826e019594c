"""The canvas widgets draw only when something changed (robot_lab.widgets.canvas.animate):
their own JavaScript in a real Chromium, driven by a model that stands in for the kernel's
side (anywidget's `get`/`on`/`off`/`send`), so that each message and each frame is counted.

A view at rest asks the page for no frames at all: its loop sleeps until the model sends
data or changes. A live chart keeps scrolling at its own rate until it is paused."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import browser_lab
import pytest

from robot_lab.widgets.canvas import _CHART_ESM, _POSE_ESM

CHROMIUM, sync_playwright = browser_lab.browser_or_skip()

# Counts the page's requestAnimationFrame calls; a model like anywidget's, which the test
# drives: window.send(msg) is a message from the kernel, window.set(key, value) a change.
_PAGE = """
<html><body><div id="view" style="width: 700px"></div><script>
window.rafCalls = 0;
const raf = window.requestAnimationFrame.bind(window);
window.requestAnimationFrame = (f) => { window.rafCalls += 1; return raf(f); };
window.makeModel = (state) => {
  const handlers = {};
  const fire = (event, ...args) => (handlers[event] || []).slice().forEach(f => f(...args));
  window.send = (msg) => fire('msg:custom', msg, []);
  window.set = (key, value) => { state[key] = value; fire('change:' + key); fire('change'); };
  return {
    get: (key) => state[key],
    on: (event, f) => { (handlers[event] = handlers[event] || []).push(f); },
    off: (event, f) => { handlers[event] = (handlers[event] || []).filter(g => g !== f); },
    send: () => {},
  };
};
</script></body></html>
"""
_RENDER = """async ([source, state]) => {
  const url = URL.createObjectURL(new Blob([source], {type: 'text/javascript'}));
  const widget = (await import(url)).default;
  widget.render({model: window.makeModel(state), el: document.getElementById('view')});
}"""


@pytest.fixture(scope='module')
def page() -> Iterator[Any]:
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=browser_lab.CHROMIUM_ARGS)
        try:
            yield browser.new_page(viewport={'width': 800, 'height': 600})
        finally:
            browser.close()


def _frames(page: Any) -> int:
    return int(page.evaluate("() => +(document.querySelector('.rl-canvas')?.dataset.frames"
                             " || 0)"))


def _quiet_for(page: Any, ms: int) -> tuple[int, int]:
    """(frames drawn, animation frames asked for) over `ms` of the page's own clock."""
    return tuple(page.evaluate("""ms => new Promise(done => {
        const frames = () => +(document.querySelector('.rl-canvas').dataset.frames || 0);
        const f0 = frames(), r0 = window.rafCalls;
        setTimeout(() => done([frames() - f0, window.rafCalls - r0]), ms);
    })""", ms))


def _at_rest(page: Any) -> tuple[int, int]:
    """What the widget does over 1 s once it has had 0.3 s to finish (after a drawn frame,
    the loop looks once more: the next frame may still move)."""
    _quiet_for(page, 300)
    return _quiet_for(page, 1000)


def test_a_robot_view_at_rest_asks_for_no_frames(page: Any) -> None:
    page.set_content(_PAGE)
    page.evaluate(_RENDER, [_POSE_ESM, {'config': {'topic': '/odom', 'height': 300},
                                        'note': ''}])
    assert browser_lab.wait_in_page(page, "() => document.querySelector('.rl-canvas')"
                                    "?.dataset.frames == '1'", None, 10), 'first frame'
    assert _at_rest(page) == (0, 0), 'a view with nothing new kept asking for frames'
    page.evaluate('() => window.send({poses: [1.5, 0.5, 0.3], twist: [0.2, 0.0], count: 1})')
    assert browser_lab.wait_in_page(page, "() => document.querySelector('.rl-canvas')"
                                    ".dataset.x == '1.500'", None, 10), 'the pose was not drawn'
    assert _frames(page) == 2
    assert _at_rest(page) == (0, 0), 'the view kept drawing after the message'
    page.evaluate("() => window.set('note', 'stopped')")
    assert browser_lab.wait_in_page(page, "() => document.querySelector('.rl-status')"
                                    ".textContent.includes('stopped')", None, 10)


def test_a_live_chart_scrolls_at_its_rate_until_paused(page: Any) -> None:
    page.set_content(_PAGE)
    config = {'series': [{'label': 'x', 'colour': '#0072B2', 'panel': 0}], 'panels': ['/x'],
              'window': 10, 'live': True, 'xlabel': 'time (s)', 'fps': 10}
    page.evaluate(_RENDER, [_CHART_ESM, {'config': config, 'frozen_at': None, 'note': ''}])
    page.evaluate('() => window.send({points: [[0, 1, 0.5, 2]], totals: [2], now: 0.5})')
    drawn, asked = _quiet_for(page, 2000)
    assert 12 <= drawn <= 22, f'a live chart at 10 fps drew {drawn} frames in 2 s'
    assert asked <= drawn + 2, f'{asked} animation frames asked for {drawn} drawn'
    page.evaluate("() => window.set('frozen_at', 0.5)")
    assert browser_lab.wait_in_page(page, "() => document.querySelector('.rl-status')"
                                    ".textContent.includes('paused')", None, 10)
    assert _at_rest(page) == (0, 0), 'a paused chart kept drawing'
