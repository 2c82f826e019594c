"""teleop_twist_keyboard in the notebook: `robot_lab.teleop()`, a pad that drives while held.

A terminal program cannot read a notebook's keys, and a student holding a key expects the
robot to move only while it is down. The pad has upstream's keys as buttons (and, once
clicked, takes the keyboard's keys themselves): a held key publishes its Twist at once and
then `rate` times a second, as a joystick teleop does; releasing it (or the pad losing
focus, or `close()`) publishes one zero and stops. The speed keys and two sliders set
`speed` and `turn`. Everything is drivable from code (`press`, `release`, `key`), and the
browser only sets `held` on the pad's model, so tests drive exactly what a click does.
"""

from __future__ import annotations

import html
import threading
from typing import TYPE_CHECKING, Any

import anywidget
import traitlets

from robot_lab.errors import GraphError
from robot_lab.keyboard_teleop.keys import LAYOUT, MOVES, SPEEDS, Drive, Velocity, twist_message
from robot_lab.widgets.canvas import SHARED_SCRIPT
from robot_lab.widgets.output import is_headless, owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import HTML, FloatSlider, Widget

__all__ = ['Teleop', 'TeleopPad', 'teleop']

_PAD_ESM = SHARED_SCRIPT + r"""
const PAD_CSS = `
.rl-teleop { display: inline-block; padding: 6px; border: 1px solid #ccc; border-radius: 6px;
  outline: none; font: 13px var(--jp-ui-font-family, sans-serif); user-select: none; }
.rl-teleop:focus { border-color: #1a73e8; box-shadow: 0 0 0 2px #1a73e833; }
.rl-teleop .rl-grid { display: grid; grid-template-columns: repeat(3, 3em); gap: 4px; }
.rl-teleop button { height: 2.6em; font: 600 15px monospace; cursor: pointer;
  border: 1px solid #bbb; border-radius: 4px; background: #f6f6f6; touch-action: none; }
.rl-teleop button.rl-held { background: #1a73e8; color: white; border-color: #1a73e8; }
.rl-teleop .rl-row { display: flex; gap: 4px; margin-top: 4px; align-items: center; }
.rl-teleop .rl-row button { width: 3em; }
.rl-teleop .rl-hint { color: #666; font-size: 12px; margin-top: 4px; max-width: 24em; }
.rl-teleop .rl-row .rl-hint { margin: 0 0 0 4px; }
`;
function render({ model, el }) {
  addStyle();
  if (!document.getElementById('rl-teleop-style')) {
    const style = document.createElement('style');
    style.id = 'rl-teleop-style';
    style.textContent = PAD_CSS;
    document.head.appendChild(style);
  }
  const keys = model.get('bindings');
  const moves = new Set(keys.moves), speeds = new Set(keys.speeds);
  const shifted = keys.shifted;  // plain key -> the strafing key above it
  const root = document.createElement('div');
  root.className = 'rl-teleop';
  root.tabIndex = 0;
  root.dataset.lmSuppressShortcuts = 'true';  // Lumino: JupyterLab's own keys stay out
  const grid = document.createElement('div');
  grid.className = 'rl-grid';
  const buttons = new Map();
  let shift = false, heldCode = '';
  const hold = (key) => { model.set('held', key); model.save_changes(); };
  const release = () => { heldCode = ''; if (model.get('held')) hold(''); };
  const button = (plain, parent) => {
    const b = document.createElement('button');
    b.dataset.key = plain;
    b.textContent = plain;
    b.addEventListener('pointerdown', (e) => {
      e.preventDefault();
      root.focus();
      b.setPointerCapture(e.pointerId);
      const key = shift && shifted[plain] ? shifted[plain] : plain;
      if (speeds.has(key)) model.send({ kind: 'key', key });
      else hold(key);
    });
    for (const end of ['pointerup', 'pointercancel', 'lostpointercapture']) {
      b.addEventListener(end, () => { if (!speeds.has(plain)) release(); });
    }
    buttons.set(plain, b);
    parent.appendChild(b);
  };
  for (const row of keys.layout) for (const key of row) button(key, grid);
  const row = (label, group) => {
    const div = document.createElement('div');
    div.className = 'rl-row';
    for (const key of group) button(key, div);
    const text = document.createElement('span');
    text.className = 'rl-hint';
    text.textContent = label;
    div.appendChild(text);
    return div;
  };
  const updown = row('up / down (+z / −z)', ['t', 'b']);
  const faster = row('speeds ±10 %: both, linear, angular', ['q', 'z', 'w', 'x', 'e', 'c']);
  const shiftBox = document.createElement('label');
  const check = document.createElement('input');
  check.type = 'checkbox';
  check.addEventListener('change', () => { shift = check.checked; relabel(); });
  shiftBox.append(check, ' shift (strafe)');
  const shiftRow = document.createElement('div');
  shiftRow.className = 'rl-row';
  shiftRow.appendChild(shiftBox);
  const hint = document.createElement('div');
  hint.className = 'rl-hint';
  hint.textContent = 'Hold a key (or click here and hold it on the keyboard): ' +
    'u i o / j k l / m , . drive, shifted keys strafe. Let go to stop.';
  root.append(grid, updown, faster, shiftRow, hint);
  el.appendChild(root);
  const relabel = () => {
    for (const [plain, b] of buttons) {
      b.textContent = shift && shifted[plain] ? shifted[plain] : plain;
    }
    show();
  };
  const show = () => {
    const held = model.get('held');
    for (const [plain, b] of buttons) {
      b.classList.toggle('rl-held', held !== '' && (plain === held || shifted[plain] === held));
    }
  };
  root.addEventListener('keydown', (e) => {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    e.preventDefault();
    e.stopPropagation();  // JupyterLab's own shortcuts (a, b, m, ...) must not see it
    if (e.repeat) return;
    if (speeds.has(e.key)) { model.send({ kind: 'key', key: e.key }); return; }
    if (e.key === 'Shift') return;
    heldCode = e.code;
    hold(moves.has(e.key) ? e.key : '');  // anything else: stop
  });
  root.addEventListener('keyup', (e) => {
    e.stopPropagation();
    if (e.code === heldCode) release();
  });
  root.addEventListener('blur', release);
  model.on('change:held', show);
  show();
  return () => { model.off('change:held', show); };
}
export default { render };
"""


class TeleopPad(anywidget.AnyWidget):
    """The buttons and the keyboard focus; `held` is the key down now ('' for none)."""

    _esm = _PAD_ESM
    held = traitlets.Unicode('').tag(sync=True)
    bindings = traitlets.Dict().tag(sync=True)


def _bindings() -> dict[str, object]:
    shifted = {'u': 'U', 'i': 'I', 'o': 'O', 'j': 'J', 'l': 'L', 'm': 'M', ',': '<',
               '.': '>'}
    return {'layout': [list(row) for row in LAYOUT], 'moves': list(MOVES),
            'speeds': list(SPEEDS), 'shifted': shifted}


class Teleop:
    """Publishes the held key's Twist on `topic` at `rate` Hz; drivable with `press()`."""

    def __init__(self, topic: str = '/cmd_vel', speed: float = 0.5, turn: float = 1.0,
                 rate: float = 10.0, stamped: bool = False, frame_id: str = '',
                 domain_id: int | None = None) -> None:
        if not rate > 0:
            raise GraphError(f'teleop rate must be above 0 Hz, not {rate}',
                             fix='pass rate=10.0 (messages a second while a key is held)')
        if frame_id and not stamped:
            raise GraphError("'frame_id' can only be set when 'stamped' is True",
                             fix='pass stamped=True, or leave frame_id out')
        from geometry_msgs.msg import Twist, TwistStamped

        from robot_lab.rclpy_session import session

        self.session = session(domain_id)
        self.topic = topic
        self.rate = rate
        self.stamped = stamped
        self.frame_id = frame_id
        self.drive = Drive(speed=float(speed), turn=float(turn))
        self.held = ''
        self.sent = 0
        self._lock = threading.Lock()
        self._closed = False
        self._pad: TeleopPad | None = None
        self._sliders: dict[str, FloatSlider] = {}
        self._status: HTML | None = None
        self._widget: Widget | None = None
        node = self.session.node
        kind = TwistStamped if stamped else Twist
        self._publisher = self.session.run_in_executor(
            lambda: node.create_publisher(kind, topic, 10))
        self._timer = self.session.run_in_executor(
            lambda: node.create_timer(1.0 / rate, self._tick))
        owned_by_cell(self)

    # -- driving --------------------------------------------------------------------
    def press(self, key: str) -> None:
        """Hold `key` down (a speed key is pressed once: it changes the speeds and keeps
        the direction); any key that is neither stops, as upstream's do."""
        if key in SPEEDS:
            self.key(key)
            return
        if key not in MOVES:
            self.release()
            return
        with self._lock:
            if self._closed:
                return
            self.drive.press(key)
            self.held = key
            self._publish()
        self._show(key)

    def release(self) -> None:
        """Let go: one zero Twist, then nothing until the next key."""
        with self._lock:
            if self._closed:
                return
            was_held = self.held
            self.held = ''
            self.drive.stop()
            if was_held:
                self._publish()
        self._show('')

    def key(self, key: str) -> None:
        """A speed key (q/z, w/x, e/c): scale the speeds by 10 %, as upstream's keys do."""
        if key not in SPEEDS:
            raise GraphError(f'{key!r} is not a speed key',
                             fix=f"use one of {' '.join(SPEEDS)}; press() drives")
        with self._lock:
            self.drive.press(key)
            if self.held:
                self._publish()
        self._show(self.held)

    @property
    def speed(self) -> float:
        return self.drive.speed

    @speed.setter
    def speed(self, value: float) -> None:
        with self._lock:
            self.drive.speed = float(value)
        self._show(self.held)

    @property
    def turn(self) -> float:
        return self.drive.turn

    @turn.setter
    def turn(self, value: float) -> None:
        with self._lock:
            self.drive.turn = float(value)
        self._show(self.held)

    @property
    def velocity(self) -> Velocity:
        """What a message now carries: linear x, y, z and angular z."""
        return self.drive.velocity

    def _tick(self) -> None:
        with self._lock:
            if self.held and not self._closed:
                self._publish()

    def _publish(self) -> None:  # with the lock held
        stamp = self.session.node.get_clock().now().to_msg() if self.stamped else None
        self._publisher.publish(
            twist_message(self.drive.velocity, self.stamped, self.frame_id, stamp))
        self.sent += 1

    # -- the widget -----------------------------------------------------------------
    def _from_pad(self, change: dict[str, Any]) -> None:
        key = str(change['new'])
        if key == self.held:
            return
        if key:
            self.press(key)
        else:
            self.release()

    def _from_browser(self, _pad: object, content: dict[str, Any], _buffers: object) -> None:
        if content.get('kind') == 'key' and content.get('key') in SPEEDS:
            self.key(str(content['key']))

    def _show(self, held: str) -> None:
        """Bring the pad, sliders and status line up to date (nothing before they exist)."""
        if self._pad is not None and self._pad.held != held:
            self._pad.held = held
        for name, value in (('speed', self.drive.speed), ('turn', self.drive.turn)):
            slider = self._sliders.get(name)
            if slider is not None and abs(slider.value - value) > 1e-12:
                slider.max = max(slider.max, value)
                slider.value = value
        if self._status is not None:
            self._status.value = self.status_html()

    def status_html(self) -> str:
        v = self.velocity
        kind = 'TwistStamped' if self.stamped else 'Twist'
        return (f'<code>{html.escape(self.topic)}</code> ({kind}): linear x {v.x:.3g} '
                f'y {v.y:.3g} z {v.z:.3g}, angular z {v.yaw:.3g} · speed '
                f'{self.drive.speed:.3g} m/s, turn {self.drive.turn:.3g} rad/s')

    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import kit_box

            self._pad = TeleopPad(bindings=_bindings())
            self._pad.observe(self._from_pad, names='held')
            self._pad.on_msg(self._from_browser)
            for name, unit, value in (('speed', 'm/s', self.drive.speed),
                                      ('turn', 'rad/s', self.drive.turn)):
                slider = widgets.FloatSlider(
                    value=value, min=0.0, max=max(2.0, 2 * value), step=0.01,
                    description=f'{name} ({unit})', readout_format='.2f',
                    style={'description_width': '7em'},
                    layout=widgets.Layout(width='22em'))
                slider.observe(lambda change, name=name: setattr(self, name, change['new']),
                               names='value')
                self._sliders[name] = slider
            self._status = widgets.HTML(self.status_html())
            self._widget = kit_box([self._pad, *self._sliders.values(), self._status])
        return self._widget

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            display(HTML(self.html_table()))
        else:
            display(self.widget)

    def html_table(self) -> str:
        """The keys and the state, for a page without a live kernel."""
        rows = ''.join('<tr>' + ''.join(f'<td><code>{html.escape(k)}</code></td>'
                                        for k in row) + '</tr>' for row in LAYOUT)
        return (f'<p>teleop on {self.status_html()}</p><table>{rows}</table>'
                '<p>hold a key to drive (<code>t.press("i")</code>, '
                '<code>t.release()</code> from code)</p>')

    def close(self, timeout: float = 1.0) -> None:
        """Stop: a zero Twist if a key was held (delivered to the subscribers, within
        `timeout`), then no publisher, no timer and no pad."""
        from rclpy.duration import Duration

        self.release()
        with self._lock:
            if self._closed:
                return
            self._closed = True
        self._publisher.wait_for_all_acked(Duration(seconds=timeout))
        node = self.session.node
        timer, publisher = self._timer, self._publisher

        def _destroy() -> None:
            node.destroy_timer(timer)
            node.destroy_publisher(publisher)

        self.session.run_in_executor(_destroy)
        if self._widget is not None:
            self._widget.close()
        if self._pad is not None:
            self._pad.close()

    def __repr__(self) -> str:
        state = 'closed' if self._closed else f'held {self.held!r}' if self.held else 'idle'
        return (f'<Teleop {self.topic} {state}: speed {self.drive.speed:.3g} '
                f'turn {self.drive.turn:.3g}, {self.sent} sent>')


def teleop(topic: str = '/cmd_vel', speed: float = 0.5, turn: float = 1.0,
           rate: float = 10.0, stamped: bool = False, frame_id: str = '',
           domain_id: int | None = None) -> Teleop:
    """A teleop pad on `topic` (upstream's keys; held keys drive, letting go stops).

    `stamped=True` publishes TwistStamped with `frame_id` (a Jazzy diff_drive_controller
    takes those); `close()` or the cell's next run stops it with a zero Twist.
    """
    return Teleop(topic, speed, turn, rate, stamped, frame_id, domain_id)
