"""turtlesim's window in a notebook: the background, the pen trails and the turtles.

The kit's turtlesim has no Qt window; it says what a window would draw on two hidden names
(see `robot_lab.turtlesim.node`): `~/_snapshot` (the trails so far, a PNG) and `~/_view`
(the turtles and new strokes, ~20 a second while watched). The view asks for the snapshot
once, then adds each message's strokes, so a turtlesim started in a terminal, or in a
launch, is watched the same way. The browser draws it (500×500 px, as the window);
headless runs get a picture.
"""

from __future__ import annotations

import base64
import io
import json
import math
import threading
import time
from typing import TYPE_CHECKING, Any

import anywidget
import traitlets

from robot_lab.widgets.canvas import SHARED_SCRIPT
from robot_lab.widgets.live_view import LiveView
from robot_lab.widgets.output import owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import Widget
    from matplotlib.figure import Figure
    from rclpy.task import Future
    from std_msgs.msg import String

    from robot_lab.widgets.canvas import Payload

__all__ = ['TurtlesimView', 'turtlesim_view']

CANVAS = 499 / 45  # the world's size in metres (as turtlesim: 500 px, 45 px a metre)
MAX_STROKES = 50_000  # then the trails come again as one snapshot
SHELLS = ['#2e7d32', '#6d4c41', '#00838f', '#558b2f', '#ad1457', '#4527a0', '#ef6c00',
          '#1565c0', '#827717', '#37474f']

_ESM = SHARED_SCRIPT + r"""
function render({ model, el }) {
  const [root, canvas, status] = mount(el, 'rl-turtlesim');
  root.style.maxWidth = '500px';
  const trails = document.createElement('canvas');
  trails.width = 500; trails.height = 500;
  const tctx = trails.getContext('2d');
  let background = [69, 86, 255], turtles = [], dirty = true, pending = [], loading = false;
  let stop = null;  // the animation (animate): an image that loads wakes it
  const shells = SHELLS;
  const stroke = (s) => {
    const [x0, y0, x1, y1, r, g, b, w] = s;
    tctx.strokeStyle = `rgb(${r},${g},${b})`; tctx.lineWidth = w; tctx.lineCap = 'square';
    tctx.beginPath(); tctx.moveTo(x0 * 45, (CANVAS - y0) * 45);
    tctx.lineTo(x1 * 45, (CANVAS - y1) * 45); tctx.stroke();
  };
  const take = (msg) => {
    if (msg.background) background = msg.background;
    if (msg.turtles) turtles = msg.turtles;
    if (msg.kind === 'reset') {
      tctx.clearRect(0, 0, 500, 500);
      pending = [];
      if (msg.png) {
        loading = true;
        const img = new Image();
        img.onload = () => {
          tctx.drawImage(img, 0, 0); loading = false;
          for (const s of pending) stroke(s);
          pending = []; dirty = true;
          if (stop) stop.wake();
        };
        img.src = 'data:image/png;base64,' + msg.png;
      }
    }
    for (const s of msg.strokes || []) { if (loading) pending.push(s); else stroke(s); }
    dirty = true;
  };
  model.on('msg:custom', take);
  model.on('change:note', () => { dirty = true; });
  const draw = () => {
    if (!dirty) return false;
    dirty = false;
    const [ctx, width] = sizeCanvas(root, canvas, 500);
    const s = width / 500;
    ctx.save(); ctx.scale(s, s);
    ctx.fillStyle = `rgb(${background.join(',')})`; ctx.fillRect(0, 0, 500, 500);
    ctx.drawImage(trails, 0, 0);
    for (const [name, x, y, th, image] of turtles) {
      ctx.save(); ctx.translate(x * 45, (CANVAS - y) * 45); ctx.rotate(-th);
      ctx.fillStyle = '#8bc34a';
      for (const [lx, ly] of [[7, 9], [7, -9], [-8, 9], [-8, -9]]) {
        ctx.beginPath(); ctx.ellipse(lx, ly, 5, 3.5, 0, 0, 2 * Math.PI); ctx.fill();
      }
      ctx.beginPath(); ctx.ellipse(15, 0, 6, 5, 0, 0, 2 * Math.PI); ctx.fill();
      ctx.fillStyle = shells[image % shells.length]; ctx.strokeStyle = '#1b1b1b';
      ctx.lineWidth = 1.2;
      ctx.beginPath(); ctx.ellipse(0, 0, 12, 10, 0, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
      ctx.restore();
    }
    ctx.restore();
    const note = model.get('note');
    const names = turtles.map((t) => `${t[0]} (${t[1].toFixed(2)}, ${t[2].toFixed(2)})`);
    status.textContent = `${model.get('node')}: ${names.join('  ') || 'no turtles'}` +
      (note ? `  \u2014  ${note}` : '');
    root.dataset.turtles = JSON.stringify(turtles);
    root.dataset.background = background.join(',');
    return true;
  };
  stop = animate(root, 30, draw, model);
  model.send({ kind: 'ready' });
  return () => { stop(); model.off('msg:custom', take); };
}
export default { render };
""".replace('SHELLS', json.dumps(SHELLS)).replace('CANVAS', repr(CANVAS))


class TurtleCanvas(anywidget.AnyWidget):
    """What the browser draws for a TurtlesimView."""

    _esm = _ESM
    node = traitlets.Unicode('/turtlesim').tag(sync=True)
    note = traitlets.Unicode('').tag(sync=True)


class TurtlesimView(LiveView):
    """Watch a turtlesim node: `.turtles`, `.background`, `.strokes` for checks."""

    headless_default = (2.0, 1.0)

    def __init__(self, node: str = '/turtlesim', domain_id: int | None = None,
                 headless_seconds: float | None = None, rate: float = 20.0) -> None:
        from rclpy.qos import QoSProfile
        from std_msgs.msg import String
        from std_srvs.srv import Trigger

        from robot_lab.rclpy_session import session

        super().__init__(rate, headless_seconds)
        self.node = node if node.startswith('/') else '/' + node
        self.background: list[int] = [69, 86, 255]
        self.turtles: list[list[Any]] = []
        self.messages = 0
        self._png: str | None = None
        self._strokes: list[list[float]] = []  # since the snapshot
        self._pending: list[list[float]] = []  # not yet sent to the browser
        self._generation = -1  # of the snapshot we have
        self._heard = -1  # of the last view message
        self._lock = threading.Lock()
        self._asking = False
        self.session = session(domain_id)
        node_ = self.session.node
        on_view = self.log.guard(self._on_view)
        self._client = self.session.run_in_executor(
            lambda: node_.create_client(Trigger, f'{self.node}/_snapshot'))
        self._subscription = self.session.run_in_executor(
            lambda: node_.create_subscription(String, f'{self.node}/_view', on_view,
                                              QoSProfile(depth=50)))
        owned_by_cell(self)

    # -- from the node ------------------------------------------------------------------
    def _on_view(self, msg: String) -> None:
        data = json.loads(msg.data)
        with self._lock:
            self.messages += 1
            self.background, self.turtles = data['background'], data['turtles']
            if data['gen'] != self._heard:  # cleared or reset: the old trails are gone
                self._heard = data['gen']
                self._strokes = []
            if data['gen'] != self._generation or len(self._strokes) > MAX_STROKES:
                self._ask_snapshot()
            self._strokes.extend(data['strokes'])
            self._pending.extend(data['strokes'])

    def _ask_snapshot(self) -> None:
        from std_srvs.srv import Trigger

        if self._asking or not self._client.service_is_ready():
            return
        self._asking = True
        future = self._client.call_async(Trigger.Request())
        future.add_done_callback(self.log.guard(self._on_snapshot))

    def _on_snapshot(self, future: Future) -> None:
        try:
            data = json.loads(future.result().message)
        finally:
            with self._lock:
                self._asking = False
        with self._lock:
            self._png = data['png']
            self._generation = data['gen']
            self._strokes = []  # drawn in the PNG (a few may come twice: harmless)
            self.background, self.turtles = data['background'], data['turtles']
        if self._feed is not None:
            self._feed.reset()

    # -- data -----------------------------------------------------------------------
    @property
    def strokes(self) -> int:
        """Pen strokes seen since the last snapshot."""
        with self._lock:
            return len(self._strokes)

    def wait_for_turtles(self, names: list[str] | None = None, timeout: float = 10.0) -> bool:
        """Block until the node has been heard from (and has these turtles)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self._lock:
                seen = {t[0] for t in self.turtles} if self.messages else None
            if seen is not None and (names is None or set(names) <= seen):
                return True
            self._closed.wait(0.05)
        return False

    def _full(self) -> Payload:
        with self._lock:
            self._pending = []
            return {'kind': 'reset', 'png': self._png, 'strokes': list(self._strokes),
                    'background': self.background, 'turtles': self.turtles}

    def _new(self) -> Payload | None:
        with self._lock:
            strokes, self._pending = self._pending, []
            return {'kind': 'append', 'strokes': strokes, 'background': self.background,
                    'turtles': self.turtles}

    # -- presentations --------------------------------------------------------------
    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import Feed

            canvas = TurtleCanvas(node=self.node)
            self._canvas = canvas
            self._feed = Feed(canvas, self._full, self._new, self.rate, self.log.guard)
            self._widget = widgets.VBox([canvas, self.log.widget],
                                        layout=widgets.Layout(max_width='520px'))
            self._widget.add_class('robot-lab-widget')
        return self._widget

    def _figure(self) -> Figure:
        """The window: background, trails, turtles (for pages without a kernel)."""
        from matplotlib.figure import Figure
        from matplotlib.image import imread

        with self._lock:
            png, strokes = self._png, list(self._strokes)
            background, turtles = list(self.background), list(self.turtles)
        fig = Figure(figsize=(4.0, 4.0), dpi=100)
        ax = fig.add_axes((0.0, 0.0, 1.0, 0.93))
        ax.set_facecolor((background[0] / 255, background[1] / 255, background[2] / 255))
        if png is not None:
            ax.imshow(imread(io.BytesIO(base64.b64decode(png)), format='png'),
                      extent=(0, CANVAS, 0, CANVAS))
        for x0, y0, x1, y1, r, g, b, w in strokes:
            ax.plot([x0, x1], [y0, y1], color=(r / 255, g / 255, b / 255),
                    linewidth=w * 0.6)
        for _name, x, y, theta, image in turtles:
            ax.plot([x], [y], marker=(3, 0, math.degrees(theta) - 90), markersize=14,
                    markeredgecolor='black',
                    color=SHELLS[int(image) % len(SHELLS)])
        ax.set_xlim(0, CANVAS)
        ax.set_ylim(0, CANVAS)
        ax.set_xticks([])
        ax.set_yticks([])
        fig.suptitle(f'{self.node}: ' + ', '.join(f'{t[0]} ({t[1]:.2f}, {t[2]:.2f})'
                                                   for t in turtles), fontsize=8)
        return fig

    def _release(self) -> None:
        super()._release()
        subscription, client = self._subscription, self._client
        node = self.session.node
        self.session.run_in_executor(lambda: (node.destroy_subscription(subscription),
                                              node.destroy_client(client)))

    def _collect_headless(self) -> None:
        """Until the turtles are seen (at most `headless_seconds`), then the snapshot."""
        self.wait_for_turtles(
            timeout=max(0.0, self._headless_seconds() - (time.monotonic() - self.t0)))
        deadline = time.monotonic() + 2.0
        while self._png is None and self.messages and time.monotonic() < deadline:
            self._closed.wait(0.05)

    def __repr__(self) -> str:
        names = ', '.join(t[0] for t in self.turtles) or 'no turtles seen yet'
        return f'<TurtlesimView {self.node}: {names}, {self.messages} messages>'


def turtlesim_view(node: str = '/turtlesim', domain_id: int | None = None,
                   headless_seconds: float | None = None) -> TurtlesimView:
    """turtlesim's window for a running turtlesim node: `robot_lab.turtlesim_view()`.

    Works for a node started anywhere on this domain (a terminal, a launch, a cell); give
    its full name when it has a namespace: `turtlesim_view('/turtlesim1/sim')`.
    """
    return TurtlesimView(node, domain_id=domain_id, headless_seconds=headless_seconds)
