"""rqt_plot in the notebook: live plots of message fields over a rolling time window.

An argument is a topic followed by a field path, `/cmd_vel/linear/x`; like rqt_plot, it
is split at the longest prefix that is a topic on the graph. A topic alone plots its one
numeric field (`/sensor/temperature` is `data`). The browser draws (widgets/canvas.py):
the kernel sends only the samples that are new, 20 times a second. With no frontend
(nbval, CI) the plot collects for a bounded time and leaves a static PNG of what it saw.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.widgets.live_view import PICTURE_SPAN, LiveView
from robot_lab.widgets.output import owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import ToggleButton, Widget
    from matplotlib.figure import Figure
    from rclpy.node import Node
    from rclpy.subscription import Subscription

    from robot_lab.widgets.canvas import Chart, Payload

__all__ = ['Plot', 'Series', 'plot', 'resolve_field_path']

# What a plot does with one message taken: (message, when it was received in ns, or None)
_Receive = Callable[[object, int | None], None]

# Colours that stay apart for colour-blind readers (Okabe–Ito).
_COLOURS = ['#0072B2', '#D55E00', '#009E73', '#CC79A7', '#E69F00', '#56B4E9', '#000000']


@dataclass
class Series:
    """One plotted field: where it comes from and the (time, value) samples received."""

    path: str
    topic: str
    field: str
    type_name: str
    samples: deque[tuple[float, float]] = dataclasses.field(
        default_factory=lambda: deque(maxlen=200_000))
    pending: list[float] = dataclasses.field(default_factory=list)  # t, v, t, v, ... unsent

    @property
    def label(self) -> str:
        """The legend's name: the whole field path, as rqt_plot shows it."""
        return f'{self.topic}/{self.field}'


def _numeric(value: object) -> float | None:
    if isinstance(value, bool):
        return float(value)
    if isinstance(value, int | float):
        return float(value)
    return None


def _default_field(cls: Any, path: str) -> str:
    """The field to plot when only a topic was named: its single numeric field."""
    fields = cls.get_fields_and_field_types()
    numeric = [name for name, kind in fields.items()
               if kind in {'float', 'double', 'int8', 'uint8', 'int16', 'uint16', 'int32',
                           'uint32', 'int64', 'uint64', 'boolean', 'octet'}]
    if len(numeric) == 1:
        return str(numeric[0])
    raise GraphError(
        f"'{path}' is a topic of type {cls.__module__.split('.')[0]}/msg/{cls.__name__}, "
        'not a numeric field',
        fix=f'name a field after the topic, e.g. {path}/{next(iter(fields), "data")}',
    )


def resolve_field_path(path: str, topics: dict[str, str]) -> tuple[str, str]:
    """Split `/topic/field/path` at the longest prefix that is a topic in `topics`."""
    if not path.startswith('/'):
        path = '/' + path
    parts = path.rstrip('/').split('/')
    for cut in range(len(parts), 1, -1):
        topic = '/'.join(parts[:cut])
        if topic in topics:
            return topic, '/'.join(parts[cut:])
    raise GraphError(
        f"no topic on the graph is a prefix of '{path}'",
        fix='start the node that publishes it, or check `robot-lab topic list` '
        f'(known: {", ".join(sorted(topics)) or "none"})',
    )


class Plot(LiveView):
    """A live plot of message fields; `.data` holds the samples for check cells.

    Times are seconds since the plot was created. Drive it from code with `pause()`,
    `resume()`, `clear()`, `snapshot()` and `close()`; the buttons do the same.
    """

    def __init__(self, *paths: str, window: float = 10.0, fps: float = 20.0,
                 timeout: float = 5.0, domain_id: int | None = None,
                 headless_seconds: float | None = None, bag: str | Path | None = None) -> None:
        if not paths:
            raise GraphError('plot() needs at least one field path',
                             fix="e.g. robot_lab.plot('/sensor/temperature')")
        super().__init__(fps, headless_seconds)
        self.window = float(window)
        self.fps = self.rate
        self.bag = Path(bag) if bag is not None else None
        self._lock = threading.Lock()
        self._paused_at: float | None = None
        # the samples a paused live view shows: those taken when it was paused
        self._frozen: dict[str, list[tuple[float, float]]] | None = None
        self._chart: Chart | None = None
        self._pause_button: ToggleButton | None = None
        self._subscriptions: list[tuple[Subscription, _Receive]] = []
        self._node: Node | None = None  # the plot's own node, taken from by `_taker`
        self._taker: threading.Thread | None = None
        self._sending = False
        self._take_lock = threading.Lock()
        if self.bag is not None:
            self.series = self._read_bag(paths)
            return
        from robot_lab.rclpy_session import session

        self.session = session(domain_id)
        self.series = self._resolve(paths, timeout)
        self._subscribe()
        owned_by_cell(self)

    # -- set-up ---------------------------------------------------------------------
    def _read_bag(self, paths: Iterable[str]) -> list[Series]:
        """Samples from a recorded bag instead of the graph: time since the bag's start."""
        from robot_lab.bag.info import bag_info
        from robot_lab.bag.read import read_topic
        from robot_lab.messages import message_class

        assert self.bag is not None
        topics = {t.name: t.type for t in bag_info(self.bag).topics}
        resolved: list[Series] = []
        for path in paths:
            topic, field_path = resolve_field_path(path, topics)
            if not field_path:
                field_path = _default_field(message_class(topics[topic]), path)
            series = Series(path, topic, field_path, topics[topic])
            columns = read_topic(self.bag, topic, [field_path])
            for t, value in zip(columns.t, columns[field_path], strict=True):
                number = _numeric(value)
                if number is None:
                    raise GraphError(
                        f"field '{field_path}' of {topic} ({topics[topic]}) is not a number",
                        fix='plot a numeric field, e.g. /cmd_vel/linear/x')
                series.samples.append((t, number))
            resolved.append(series)
        last = max((s.samples[-1][0] for s in resolved if s.samples), default=0.0)
        self.window = max(last, 1e-3)
        self._paused_at = last  # a recording does not move: its view is fixed
        return resolved

    def _resolve(self, paths: Iterable[str], timeout: float) -> list[Series]:
        """Find each path's topic, waiting (bounded) for discovery to show it."""
        from robot_lab.messages import field_value, message_class

        deadline = time.monotonic() + timeout
        pending = list(paths)
        resolved: list[Series] = []
        while True:
            topics = {name: types[0] for name, types in
                      self.session.node.get_topic_names_and_types() if types}
            try:
                for path in list(pending):
                    topic, field_path = resolve_field_path(path, topics)
                    cls = message_class(topics[topic])
                    if not field_path:
                        field_path = _default_field(cls, path)
                    if _numeric(field_value(cls(), field_path)) is None:
                        raise GraphError(
                            f"field '{field_path}' of {topic} ({topics[topic]}) is not a number",
                            fix='plot a numeric field, e.g. /cmd_vel/linear/x',
                        )
                    resolved.append(Series(path, topic, field_path, topics[topic]))
                    pending.remove(path)
                return resolved
            except GraphError:
                if time.monotonic() >= deadline:
                    raise
                self._closed.wait(0.05)  # discovery still running: look again

    def _subscribe(self) -> None:
        """Subscribe on a node of the plot's own that no executor spins, and take what
        arrived `fps` times a second from a thread of its own.

        An executor wakes (and rebuilds its wait set in Python) for every message: two
        topics at 20 Hz cost the kernel ~2.5 % of a core that way, against ~1 % taking the
        messages in batches; the plot draws at `fps` anyway. Samples keep the time each
        message was received, not when it was taken.
        """
        from rclpy.qos import qos_profile_sensor_data

        from robot_lab.messages import message_class

        by_topic: dict[str, list[Series]] = {}
        for series in self.series:
            by_topic.setdefault(series.topic, []).append(series)
        self._node = self.session.hidden_node(f'plot_{id(self):x}')
        for topic, group in by_topic.items():
            cls = message_class(group[0].type_name)
            # Best effort matches reliable and best-effort publishers alike.
            sub = self._node.create_subscription(cls, topic, lambda _m: None,
                                                 qos_profile_sensor_data)
            # Guarded per message, as a callback was: one bad message is logged, the
            # plot keeps taking the others.
            self._subscriptions.append((sub, self.log.guard(self._receiver(group))))
        self._taker = threading.Thread(target=self.log.guard(self._take_loop), daemon=True,
                                       name='robot_lab-plot')
        self._taker.start()

    def _take_loop(self) -> None:
        period = 1.0 / max(self.fps, 1.0)
        while not self._closed.wait(period):
            self._take()
            if self._sending and self._feed is not None:
                self._feed.tick()  # the same wake-up sends the new samples to the page

    def _take(self) -> None:
        """Take every message that has arrived (under a lock: `pause()` takes too)."""
        with self._take_lock:
            for sub, receive in self._subscriptions:
                with sub.handle:
                    while not self._closed.is_set():
                        taken = sub.handle.take_message(sub.msg_type, False)
                        if taken is None:
                            break
                        msg, info = taken
                        receive(msg, info.get('received_timestamp'))

    def _receiver(self, group: list[Series]) -> _Receive:
        from robot_lab.messages import field_value

        def _on_message(msg: object, received_ns: int | None = None) -> None:
            now = time.monotonic() - self.t0
            if received_ns:  # system clock, ns: when it arrived, not when it was taken
                now -= max(0.0, time.time() - received_ns / 1e9)
            streaming = self._feed is not None  # nobody to send to: keep nothing pending
            with self._lock:
                for series in group:
                    value = _numeric(field_value(msg, series.field))
                    if value is not None:
                        series.samples.append((now, value))
                        if streaming and self._paused_at is None:
                            series.pending.extend((round(now, 4), value))

        return _on_message

    # -- data -----------------------------------------------------------------------
    @property
    def data(self) -> dict[str, list[tuple[float, float]]]:
        """Field path -> [(seconds since start, value), ...] received so far."""
        with self._lock:
            return {s.path: list(s.samples) for s in self.series}

    def values(self, path: str, last: float | None = None) -> list[float]:
        """The values of one series, optionally only those of the `last` seconds."""
        samples = self.data[self._key(path)]
        if last is not None:
            now = self._paused_at if self.bag is not None else time.monotonic() - self.t0
            since = (now or 0.0) - last
            samples = [s for s in samples if s[0] >= since]
        return [v for _, v in samples]

    def _key(self, path: str) -> str:
        for series in self.series:
            if path in (series.path, f'{series.topic}/{series.field}'):
                return series.path
        raise KeyError(f'{path!r} is not plotted here (plotted: '
                       f'{", ".join(s.path for s in self.series)})')

    def wait_for_samples(self, count: int = 1, timeout: float = 5.0) -> bool:
        """Block until every series has `count` samples (or the timeout); True if so."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self._lock:
                if all(len(s.samples) >= count for s in self.series):
                    return True
            self._closed.wait(0.02)
        return False

    def clear(self) -> None:
        with self._lock:
            for series in self.series:
                series.samples.clear()
                series.pending.clear()
        if self._frozen is not None:
            self._frozen = {path: [] for path in self._frozen}
        if self._feed is not None:
            self._feed.reset()

    def pause(self) -> None:
        """Freeze the view (samples keep arriving in `.data`)."""
        if self._paused_at is None:
            if self.bag is None:
                self._take()  # what arrived before the pause is in the frozen view
                # and nothing else: a sample taken later can carry an earlier receive time
                self._frozen = self.data
            self._paused_at = time.monotonic() - self.t0
        if self._chart is not None and self._pause_button is not None:
            self._chart.frozen_at = self._paused_at
            self._pause_button.value = True

    def resume(self) -> None:
        """Follow the data again; the view gets what arrived while it was frozen."""
        if self.bag is not None:
            return  # a recording's view is fixed
        self._paused_at = None
        self._frozen = None
        if self._chart is not None and self._pause_button is not None:
            self._pause_button.value = False
            self._chart.frozen_at = None
        if self._feed is not None:
            self._feed.reset()

    @property
    def paused(self) -> bool:
        return self._paused_at is not None

    # -- the static picture (headless runs, bags in a static page) -------------------
    def _figure(self) -> Figure:
        """The current window, drawn with matplotlib (no live frontend needed)."""
        from matplotlib.figure import Figure

        end = self._paused_at if self._paused_at is not None else time.monotonic() - self.t0
        start = end - self.window
        shift = 0.0 if self.bag else end  # live: x is "seconds before now"
        data = self.data if self._frozen is None else self._frozen
        topics = list(dict.fromkeys(s.topic for s in self.series))
        fig = Figure(figsize=(8.0, 1.1 + 1.7 * len(topics)), dpi=100)
        axes = dict(zip(topics, fig.subplots(len(topics), 1, squeeze=False)[:, 0],
                        strict=True))
        for index, series in enumerate(self.series):
            points = [p for p in data[series.path] if start <= p[0] <= end]
            axes[series.topic].plot([p[0] - shift for p in points], [p[1] for p in points],
                                    color=_COLOURS[index % len(_COLOURS)], linewidth=1.6,
                                    label=series.label)
        for topic, ax in axes.items():
            visible = [v for line in ax.get_lines() for v in line.get_ydata()]
            ax.set_ylim(*_autoscale(visible))
            ax.set_title(topic, loc='left', fontsize=10, color='#333333')
            ax.set_xlim(*((0.0, self.window) if self.bag else (-self.window, 0.0)))
            ax.grid(True, color='#e5e5e5', linewidth=0.8)
            # Legend on the title's line, right-aligned: it never hides the data.
            ax.legend(loc='lower right', bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False,
                      ncol=4, borderaxespad=0.1)
            for side in ('top', 'right'):
                ax.spines[side].set_visible(False)
            ax.tick_params(labelsize=8)
        last = list(axes.values())[-1]
        for ax in axes.values():
            if ax is not last:
                ax.tick_params(labelbottom=False)
        last.set_xlabel(self._xlabel(), fontsize=9)
        fig.tight_layout(h_pad=0.6)
        return fig

    def _xlabel(self) -> str:
        return ('time since the start of the bag (s)' if self.bag
                else 'time relative to now (s)')

    # -- the live view: the browser draws ------------------------------------------
    def _full(self) -> Payload:
        """Every sample in the window (and forget what was pending: it is included)."""
        now = time.monotonic() - self.t0
        since = -math.inf if self.bag else now - self.window - 1.0
        with self._lock:
            points = []
            for series in self.series:
                series.pending.clear()
                points.append([x for t, v in series.samples if t >= since
                               for x in (round(t, 4), v)])
            totals = [len(s.samples) for s in self.series]
        return {'kind': 'reset', 'points': points, 'totals': totals, 'now': now}

    def _new(self) -> Payload | None:
        """The samples that arrived since the last send; None when nothing did or paused."""
        if self._paused_at is not None:
            return None
        with self._lock:
            if not any(s.pending for s in self.series):
                return None
            points = []
            for series in self.series:
                points.append(series.pending)
                series.pending = []
            totals = [len(s.samples) for s in self.series]
        return {'kind': 'append', 'points': points, 'totals': totals,
                'now': time.monotonic() - self.t0}

    @property
    def redraws(self) -> int:
        """How many updates the live view has sent to the browser."""
        return self._feed.sent if self._feed is not None else 0

    @property
    def widget(self) -> Widget:
        """The live view: pause/clear buttons and the chart the browser draws."""
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import Chart, Feed

            topics = list(dict.fromkeys(s.topic for s in self.series))
            config = {
                'series': [{'label': s.label, 'colour': _COLOURS[i % len(_COLOURS)],
                            'panel': topics.index(s.topic)}
                           for i, s in enumerate(self.series)],
                'panels': topics, 'window': self.window, 'live': self.bag is None,
                'xlabel': self._xlabel(), 'fps': 30,
            }
            chart = Chart(config=config, frozen_at=self._paused_at)
            self._chart = self._canvas = chart
            self._feed = Feed(chart, self._full, self._new, self.fps, self.log.guard)
            pause = self._pause_button = widgets.ToggleButton(
                value=self.paused, description='Pause', icon='pause',
                tooltip='freeze the view', layout=widgets.Layout(width='7em'),
                disabled=self.bag is not None)
            clear = widgets.Button(description='Clear', icon='eraser',
                                   layout=widgets.Layout(width='7em'))
            pause.observe(self._on_pause, names='value')
            clear.on_click(lambda _b: self.clear())
            toolbar = widgets.HBox([pause, clear])
            self._widget = widgets.VBox([toolbar, chart, self.log.widget],
                                        layout=widgets.Layout(max_width='960px'))
            self._widget.add_class('robot-lab-widget')
        return self._widget

    def _on_pause(self, change: dict[str, object]) -> None:
        if change['new']:
            self.pause()
        else:
            self.resume()

    def start(self) -> Plot:
        """Start sending new samples to the browser `fps` times a second."""
        _ = self.widget
        if self.bag is None:
            self._sending = True  # `_take_loop` ticks the feed: no thread of its own
        return self

    def _release(self) -> None:
        if self.bag is not None:
            return
        if self._pause_button is not None:
            self._pause_button.disabled = True
        super()._release()
        taker = self._taker
        if taker is not None and taker is not threading.current_thread():
            taker.join(timeout=2.0)
        with self._take_lock:  # a `pause()` from another thread may be taking
            self._subscriptions = []
            node, self._node = self._node, None
            if node is not None:
                with contextlib.suppress(Exception):  # the context may be shut down already
                    node.destroy_node()

    def _headless_seconds(self) -> float:
        if self.headless_seconds is not None:
            return self.headless_seconds
        return min(self.window, super()._headless_seconds())

    def _collect_headless(self) -> None:
        if self.bag is None:  # a bag's plot is complete from the start
            super()._collect_headless()

    def _picture_ready(self) -> bool:
        """Every series holds PICTURE_SPAN seconds of samples (a line, not a dot)."""
        with self._lock:
            return all(len(s.samples) >= 2
                       and s.samples[-1][0] - s.samples[0][0] >= PICTURE_SPAN
                       for s in self.series)

    def __repr__(self) -> str:
        counts = ', '.join(f'{s.path}: {len(s.samples)} samples' for s in self.series)
        return f'<Plot {counts}>'


def _autoscale(values: list[float]) -> tuple[float, float]:
    """Y limits around the visible values with a margin; a flat line gets a band."""
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return (-1.0, 1.0)
    low, high = min(finite), max(finite)
    span = high - low
    minimum = max(0.2, 0.02 * abs(high))
    if span < minimum:
        middle = (low + high) / 2
        return (middle - minimum / 2 - 0.05 * minimum, middle + minimum / 2 + 0.05 * minimum)
    return (low - 0.1 * span, high + 0.1 * span)


def plot(*paths: str, window: float = 10.0, fps: float = 20.0, timeout: float = 5.0,
         domain_id: int | None = None, headless_seconds: float | None = None,
         bag: str | Path | None = None) -> Plot:
    """Plot message fields live: `robot_lab.plot('/sensor/temperature', '/cmd_vel/linear/x')`.

    `window` is the visible time span in seconds. Shown as a cell's result it draws
    live in JupyterLab; headless it collects `headless_seconds` and shows a PNG. With
    `bag=` it plots what a recorded bag holds, from the bag's start to its end.
    """
    return Plot(*paths, window=window, fps=fps, timeout=timeout, domain_id=domain_id,
                headless_seconds=headless_seconds, bag=bag)
