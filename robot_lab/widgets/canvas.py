"""Widgets the browser draws: the kernel sends samples, a small canvas script draws them.

A PNG per frame cost the kernel about a fifth of a core at 20 frames/s (matplotlib and
PNG encoding); sending only the samples that are new costs it about a percent
(`bench/bench_widgets.py`). The scripts are inline ES modules run by anywidget, with no
library and nothing fetched at run time: the course works offline and from the wheel.

A view asks for everything when it appears (`ready`): a reloaded page or a second view of
the same widget starts complete, and the kernel keeps sending only what is new.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, TypeAlias

import anywidget
import traitlets

if TYPE_CHECKING:
    from ipywidgets import VBox, Widget

__all__ = ['SHARED_SCRIPT', 'Chart', 'Feed', 'Payload', 'PoseCanvas', 'StyleBeacon', 'kit_box']

# A message to a canvas script: JSON, its `kind` says what to do ('reset', 'append', ...).
Payload: TypeAlias = dict[str, object]

# Shared by every robot_lab widget: a disconnected widget (kernel restarted or gone) is
# greyed out and says so, instead of a tiny chain icon on controls that look usable.
_STYLE = r"""
const STYLE_ID = 'robot-lab-style';
const CSS = `
.robot-lab-widget.jupyter-widgets-disconnected { opacity: .5; pointer-events: none; }
.robot-lab-widget.jupyter-widgets-disconnected::after {
  content: 'disconnected: the kernel restarted or stopped — run the cell again';
  color: #cf222e; font-size: 12px; padding: 2px 0; }
.rl-canvas { max-width: 960px; font: 12px var(--jp-ui-font-family, sans-serif); }
.rl-canvas canvas { display: block; width: 100%; }
.rl-status { color: #666; font-size: 12px; min-height: 1.4em; white-space: pre; }
`;
function addStyle() {
  if (document.getElementById(STYLE_ID)) return;
  const style = document.createElement('style');
  style.id = STYLE_ID;
  style.textContent = CSS;
  document.head.appendChild(style);
  // A slider keeps keyboard focus after a drag, and the arrow keys would then change a
  // parameter unnoticed: a robot_lab slider lets go of the focus when the mouse does.
  document.addEventListener('pointerup', () => setTimeout(() => {
    const active = document.activeElement;
    if (active && active.closest && active.closest('.robot-lab-widget .widget-slider')) {
      active.blur();
    }
  }, 0), true);
}
function mount(el, kind) {  // [root, canvas, status line], in the widget's element
  addStyle();
  const root = document.createElement('div');
  root.className = 'rl-canvas ' + kind;
  const canvas = document.createElement('canvas');
  const status = document.createElement('div');
  status.className = 'rl-status';
  root.append(canvas, status);
  el.appendChild(root);
  return [root, canvas, status];
}
function sizeCanvas(root, canvas, height) {
  const width = Math.max(200, Math.min(root.clientWidth || 800, 960));
  const dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(width * dpr) || canvas.height !== Math.round(height * dpr)) {
    canvas.width = Math.round(width * dpr);
    canvas.height = Math.round(height * dpr);
    canvas.style.height = height + 'px';
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, width, height);
  return [ctx, width];
}
function niceStep(span, count) {
  const raw = span / Math.max(1, count);
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const n = raw / mag;
  return mag * (n < 1.5 ? 1 : n < 3 ? 2 : n < 7 ? 5 : 10);
}
function ticks(lo, hi, count) {
  const step = niceStep(hi - lo, count);
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) {
    out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  }
  return [out, step];
}
function fmt(v, step) {
  const digits = Math.max(0, Math.min(6, -Math.floor(Math.log10(step) + 1e-9)));
  return v.toFixed(digits);
}
// Draw at most `fps` frames a second, only while the widget is on screen, and only while
// something moves or changed: `frame()` returns false when it had nothing to draw, and the
// loop then sleeps until the model sends data or changes (or the widget comes back into
// view). A loop that asked for every animation frame kept a page's renderer busy 60 times
// a second for nothing (in headless Chromium, 0.5 CPU-s per 10 s with no drawing at all);
// a notebook left open with a robot view should cost a laptop nothing.
function animate(root, fps, frame, model) {
  let handle = 0, timer = 0, last = -Infinity, frames = 0, seen = true, stopped = false;
  const gap = 1000 / fps;
  const wake = () => {
    if (stopped || handle || timer || !root.isConnected || !seen) return;
    const wait = gap - (performance.now() - last);
    if (wait > 4) timer = setTimeout(() => { timer = 0; wake(); }, wait);  // 4 ms: jitter
    else handle = requestAnimationFrame(loop);
  };
  const loop = () => {
    handle = 0;
    if (stopped || !root.isConnected || !seen) return;  // the observer below wakes it
    if (frame()) {
      last = performance.now();
      frames += 1;
      root.dataset.frames = String(frames);
      wake();
    }
  };
  const watch = new IntersectionObserver((entries) => {
    seen = entries[entries.length - 1].isIntersecting;
    wake();
  });
  watch.observe(root);
  model.on('msg:custom', wake);
  model.on('change', wake);
  wake();
  const stop = () => {
    stopped = true;
    cancelAnimationFrame(handle); clearTimeout(timer); watch.disconnect();
    model.off('msg:custom', wake); model.off('change', wake);
  };
  stop.wake = wake;  // for a change the model does not carry (an image that loaded)
  return stop;
}
"""

SHARED_SCRIPT = _STYLE  # mount, sizeCanvas, animate…: for the other modules' canvas scripts

_CHART_ESM = _STYLE + r"""
function autoscale(values) {
  const finite = values.filter(Number.isFinite);
  if (!finite.length) return [-1, 1];
  let lo = Infinity, hi = -Infinity;
  for (const v of finite) { if (v < lo) lo = v; if (v > hi) hi = v; }
  const span = hi - lo, minimum = Math.max(0.2, 0.02 * Math.abs(hi));
  if (span < minimum) {
    const mid = (lo + hi) / 2, half = minimum / 2 + 0.05 * minimum;
    return [mid - half, mid + half];
  }
  return [lo - 0.1 * span, hi + 0.1 * span];
}
function needsRescale(cur, want) {
  if (want[0] < cur[0] || want[1] > cur[1]) return true;
  return (want[1] - want[0]) < 0.25 * (cur[1] - cur[0]);
}
function render({ model, el }) {
  const cfg = model.get('config');
  const [root, canvas, status] = mount(el, 'rl-chart');
  const series = cfg.series.map((s) => ({ ...s, t: [], v: [], total: 0 }));
  const ylims = {};
  let now = 0, nowAt = performance.now(), dirty = true;
  const take = (msg) => {
    if (msg.kind === 'reset') for (const s of series) { s.t = []; s.v = []; }
    (msg.points || []).forEach((pts, i) => {
      const s = series[i];
      for (let k = 0; k < pts.length; k += 2) { s.t.push(pts[k]); s.v.push(pts[k + 1]); }
    });
    (msg.totals || []).forEach((n, i) => { series[i].total = n; });
    if (msg.now !== undefined) { now = msg.now; nowAt = performance.now(); }
    dirty = true;
  };
  model.on('msg:custom', take);
  const changed = () => { dirty = true; };
  model.on('change:frozen_at', changed);
  model.on('change:note', changed);
  const draw = () => {
    const frozen = model.get('frozen_at');
    const moving = cfg.live && frozen === null;
    if (!dirty && !moving) return false;
    dirty = false;
    const panels = cfg.panels.length, panelH = 150, axisH = 34;
    const [ctx, width] = sizeCanvas(root, canvas, panels * panelH + axisH);
    const end = cfg.live ? (frozen ?? now + (performance.now() - nowAt) / 1000) : cfg.window;
    const start = end - cfg.window, shift = cfg.live ? end : 0;
    if (cfg.live) {  // keep one second beyond the window, so a line enters from the edge
      for (const s of series) {
        let cut = 0;
        while (cut < s.t.length && s.t[cut] < start - 1) cut += 1;
        if (cut) { s.t.splice(0, cut); s.v.splice(0, cut); }
      }
    }
    const left = 58, right = 12, plotW = width - left - right;
    const X = (t) => left + (t - start) / (end - start) * plotW;
    const [xt, xs] = ticks(start - shift, end - shift, Math.max(2, Math.floor(plotW / 90)));
    ctx.font = '11px sans-serif';
    cfg.panels.forEach((title, p) => {
      const y0 = p * panelH + 24, h = panelH - 34;
      const mine = series.filter((s) => s.panel === p);
      const visible = [];
      for (const s of mine) {
        for (let k = 0; k < s.t.length; k++) {
          if (s.t[k] >= start && s.t[k] <= end) visible.push(s.v[k]);
        }
      }
      const want = autoscale(visible);
      if (!ylims[p] || needsRescale(ylims[p], want)) ylims[p] = want;
      const [lo, hi] = ylims[p];
      const Y = (v) => y0 + h - (v - lo) / (hi - lo) * h;
      ctx.strokeStyle = '#e5e5e5'; ctx.lineWidth = 1; ctx.fillStyle = '#555';
      const [yt, ys] = ticks(lo, hi, 4);
      ctx.textAlign = 'right'; ctx.textBaseline = 'middle';
      for (const v of yt) {
        const y = Math.round(Y(v)) + 0.5;
        ctx.beginPath(); ctx.moveTo(left, y); ctx.lineTo(left + plotW, y); ctx.stroke();
        ctx.fillText(fmt(v, ys), left - 6, y);
      }
      ctx.textAlign = 'center'; ctx.textBaseline = 'top';
      for (const v of xt) {
        const x = Math.round(X(v + shift)) + 0.5;
        ctx.beginPath(); ctx.moveTo(x, y0); ctx.lineTo(x, y0 + h); ctx.stroke();
        if (p === panels - 1) ctx.fillText(fmt(v, xs), x, y0 + h + 4);
      }
      ctx.strokeStyle = '#999';
      ctx.beginPath(); ctx.moveTo(left + 0.5, y0); ctx.lineTo(left + 0.5, y0 + h + 0.5);
      ctx.lineTo(left + plotW, y0 + h + 0.5); ctx.stroke();
      ctx.textBaseline = 'alphabetic'; ctx.font = '12px sans-serif';
      ctx.textAlign = 'left'; ctx.fillStyle = '#333'; ctx.fillText(title, left, y0 - 8);
      let lx = left + plotW;  // the legend, right-aligned on the title's line
      ctx.textAlign = 'right';
      for (const s of [...mine].reverse()) {
        ctx.fillStyle = '#333'; ctx.fillText(s.label, lx, y0 - 8);
        lx -= ctx.measureText(s.label).width + 6;
        ctx.fillStyle = s.colour; ctx.fillRect(lx - 16, y0 - 13, 16, 3);
        lx -= 28;
      }
      ctx.font = '11px sans-serif';
      ctx.save(); ctx.beginPath(); ctx.rect(left, y0 - 1, plotW, h + 2); ctx.clip();
      ctx.lineWidth = 1.6; ctx.lineJoin = 'round';
      for (const s of mine) {
        ctx.strokeStyle = s.colour; ctx.beginPath();
        let on = false;
        for (let k = 0; k < s.t.length; k++) {
          const y = Y(s.v[k]);
          if (!Number.isFinite(y)) { on = false; continue; }
          if (on) ctx.lineTo(X(s.t[k]), y); else { ctx.moveTo(X(s.t[k]), y); on = true; }
        }
        ctx.stroke();
      }
      ctx.restore();
    });
    ctx.textAlign = 'center'; ctx.textBaseline = 'bottom'; ctx.fillStyle = '#555';
    ctx.fillText(cfg.xlabel, left + plotW / 2, panels * panelH + axisH - 2);
    const counts = series.map((s) => `${s.label}: ${s.total}`).join(', ');
    const note = model.get('note') || (frozen !== null && cfg.live ? 'paused' : '');
    const text = `${counts} samples${note ? '  \u2014  ' + note : ''}`;
    if (status.textContent !== text) status.textContent = text;
    root.dataset.ylims = JSON.stringify(cfg.panels.map((_, p) => ylims[p]));
    return true;
  };
  const stop = animate(root, cfg.fps, draw, model);
  model.send({ kind: 'ready' });
  return () => { stop(); model.off('msg:custom', take); };
}
export default { render };
"""

_POSE_ESM = _STYLE + r"""
function render({ model, el }) {
  const cfg = model.get('config');
  const [root, canvas, status] = mount(el, 'rl-pose');
  let xs = [], ys = [], pose = [0, 0, 0], twist = [0, 0], count = 0, dirty = true;
  let view = null;  // [xmin, xmax, ymin, ymax] in metres: grows to keep the robot in sight
  const take = (msg) => {
    if (msg.kind === 'reset') { xs = []; ys = []; view = null; }
    const p = msg.poses || [];
    for (let k = 0; k < p.length; k += 3) {
      xs.push(p[k]); ys.push(p[k + 1]); pose = [p[k], p[k + 1], p[k + 2]];
    }
    if (xs.length > 20000) { xs = xs.slice(-10000); ys = ys.slice(-10000); }
    if (msg.twist) twist = msg.twist;
    if (msg.count !== undefined) count = msg.count;
    dirty = true;
  };
  model.on('msg:custom', take);
  model.on('change:note', () => { dirty = true; });
  const include = (x, y) => {
    const m = 0.5;
    if (!view) view = [-1, 1, -1, 1];
    if (x - m < view[0]) view[0] = x - m;
    if (x + m > view[1]) view[1] = x + m;
    if (y - m < view[2]) view[2] = y - m;
    if (y + m > view[3]) view[3] = y + m;
  };
  const draw = () => {
    if (!dirty) return false;
    dirty = false;
    const height = cfg.height;
    const [ctx, width] = sizeCanvas(root, canvas, height);
    include(pose[0], pose[1]);
    for (let k = Math.max(0, xs.length - 2000); k < xs.length; k++) include(xs[k], ys[k]);
    const pad = 30;
    const scale = Math.min((width - 2 * pad) / (view[1] - view[0]),
                           (height - 2 * pad) / (view[3] - view[2]));
    const cx = (view[0] + view[1]) / 2, cy = (view[2] + view[3]) / 2;
    const SX = (x) => width / 2 + (x - cx) * scale, SY = (y) => height / 2 - (y - cy) * scale;
    const wx = (width / 2) / scale, wy = (height / 2) / scale;
    const [gx, step] = ticks(cx - wx, cx + wx, Math.max(2, Math.floor(width / 90)));
    const [gy] = ticks(cy - wy, cy + wy, Math.max(2, Math.floor(height / 90)));
    ctx.lineWidth = 1; ctx.font = '11px sans-serif'; ctx.fillStyle = '#777';
    ctx.textAlign = 'left'; ctx.textBaseline = 'top';
    for (const v of gx) {
      const x = Math.round(SX(v)) + 0.5;
      ctx.strokeStyle = v === 0 ? '#bbb' : '#eee';
      ctx.beginPath(); ctx.moveTo(x, 0); ctx.lineTo(x, height); ctx.stroke();
      ctx.fillText(fmt(v, step) + ' m', x + 3, height - 14);
    }
    for (const v of gy) {
      const y = Math.round(SY(v)) + 0.5;
      ctx.strokeStyle = v === 0 ? '#bbb' : '#eee';
      ctx.beginPath(); ctx.moveTo(0, y); ctx.lineTo(width, y); ctx.stroke();
      ctx.fillText(fmt(v, step) + ' m', 3, y + 2);
    }
    ctx.strokeStyle = '#56B4E9'; ctx.lineWidth = 2; ctx.lineJoin = 'round'; ctx.beginPath();
    for (let k = 0; k < xs.length; k++) {
      if (k) ctx.lineTo(SX(xs[k]), SY(ys[k])); else ctx.moveTo(SX(xs[k]), SY(ys[k]));
    }
    ctx.stroke();
    const r = Math.max(9, 0.18 * scale), [x, y, th] = pose;
    ctx.save(); ctx.translate(SX(x), SY(y)); ctx.rotate(-th);
    ctx.fillStyle = '#0072B2'; ctx.strokeStyle = '#023e62'; ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.arc(0, 0, r, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    ctx.fillStyle = '#E69F00';
    ctx.beginPath(); ctx.moveTo(r * 1.05, 0); ctx.lineTo(-r * 0.35, r * 0.55);
    ctx.lineTo(-r * 0.35, -r * 0.55); ctx.closePath(); ctx.fill();
    ctx.restore();
    const deg = ((th * 180 / Math.PI) % 360 + 540) % 360 - 180;
    const note = model.get('note');
    status.textContent = `${cfg.topic}: x ${x.toFixed(2)} m   y ${y.toFixed(2)} m   ` +
      `\u03b8 ${deg.toFixed(0)}\u00b0   |   v ${twist[0].toFixed(2)} m/s   ` +
      `\u03c9 ${twist[1].toFixed(2)} rad/s   |   ${count} messages` +
      (note ? `  \u2014  ${note}` : '');
    root.dataset.x = x.toFixed(3); root.dataset.y = y.toFixed(3);
    root.dataset.theta = th.toFixed(3);
    return true;
  };
  const stop = animate(root, 30, draw, model);
  model.send({ kind: 'ready' });
  return () => { stop(); model.off('msg:custom', take); };
}
export default { render };
"""

_BEACON_ESM = _STYLE + r"""
function render({ el }) { addStyle(); el.style.display = 'none'; }
export default { render };
"""


class Chart(anywidget.AnyWidget):
    """Time series in stacked panels, one per topic; fed by `Feed`."""

    _esm = _CHART_ESM
    # series: [{label, colour, panel}], panels: [title], window (s), live, xlabel, fps
    config = traitlets.Dict().tag(sync=True)
    frozen_at = traitlets.Float(None, allow_none=True).tag(sync=True)
    note = traitlets.Unicode('').tag(sync=True)


class PoseCanvas(anywidget.AnyWidget):
    """A robot's 2-D pose and trail seen from above; fed by `Feed`."""

    _esm = _POSE_ESM
    config = traitlets.Dict().tag(sync=True)  # topic, height (px)
    note = traitlets.Unicode('').tag(sync=True)


class StyleBeacon(anywidget.AnyWidget):
    """Invisible; loads the shared style so a plain ipywidgets box shows when disconnected."""

    _esm = _BEACON_ESM


def kit_box(children: list[Widget], **layout: str) -> VBox:
    """A VBox of robot_lab's: greyed out and labelled when its kernel is gone."""
    import ipywidgets as widgets

    box = widgets.VBox([*children, StyleBeacon()], layout=widgets.Layout(**layout))
    box.add_class('robot-lab-widget')
    return box


class Feed:
    """Sends what is new to a browser-drawn widget `rate` times a second, from its own thread.

    `full()` returns everything (a `reset` message) and must also forget what `pending()`
    would send next, under the same lock, so a view never gets a sample twice.
    """

    def __init__(self, widget: anywidget.AnyWidget, full: Callable[[], Payload],
                 pending: Callable[[], Payload | None], rate: float,
                 guard: Callable[[Callable[[], None]], Callable[[], None]]) -> None:
        self.widget = widget
        self.full = full
        self.pending = pending
        self.period = 1.0 / rate
        self.sent = 0
        self._guard = guard
        self._closed = threading.Event()
        self._thread: threading.Thread | None = None
        widget.on_msg(self._on_msg)

    def _on_msg(self, _widget: object, content: object, _buffers: object) -> None:
        if isinstance(content, dict) and content.get('kind') == 'ready':
            self.reset()

    def reset(self) -> None:
        """Send every view the whole picture (a view appeared, or a pause ended)."""
        if not self._closed.is_set():
            self.widget.send(self.full())

    def start(self) -> None:
        if self._thread is None or not self._thread.is_alive():
            self._thread = threading.Thread(target=self._guard(self._loop), daemon=True,
                                            name='robot_lab-feed')
            self._thread.start()

    def _loop(self) -> None:
        while not self._closed.wait(self.period):
            self.tick()

    def tick(self) -> None:
        """Send what is new, if anything: from the feed's thread, or from an owner that
        already wakes `rate` times a second (a plot taking its messages) and so saves a
        second thread's wake-ups."""
        if self._closed.is_set():
            return
        payload = self.pending()
        if payload is not None:
            self.widget.send(payload)
            self.sent += 1

    def close(self) -> None:
        self._closed.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
