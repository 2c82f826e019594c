"""rqt_console in the notebook: log records from /rosout or a launch, filtered by level and node.

Every rclpy node publishes its log records on /rosout (rcl_interfaces/msg/Log) besides
printing them; the console subscribes with the same durable QoS the publishers use, so
records from just before it started (the nodes' "started" lines) show up too. With a
LaunchHandle it shows the launch's own output instead (what `ros2 launch` prints).
"""

from __future__ import annotations

import html
import re
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

from robot_lab.errors import GraphError
from robot_lab.widgets.output import WidgetLog, is_headless, owned_by_cell, scroll_box

if TYPE_CHECKING:
    from ipywidgets import Dropdown, Widget
    from rcl_interfaces.msg import Log
    from rclpy.subscription import Subscription

    from robot_lab.launch.api import LaunchHandle

__all__ = ['LEVELS', 'Console', 'LogRecord', 'console']

# rcl_interfaces/msg/Log severities, as `ros2 run`/`ros2 launch` print them.
LEVELS: dict[str, int] = {'DEBUG': 10, 'INFO': 20, 'WARN': 30, 'ERROR': 40, 'FATAL': 50}
_NAMES = {value: name for name, value in LEVELS.items()}
_COLOURS = {'DEBUG': '#6e7781', 'INFO': '#24292f', 'WARN': '#9a6700', 'ERROR': '#cf222e',
            'FATAL': '#cf222e'}
_ALL = '(all nodes)'


@dataclass(frozen=True)
class LogRecord:
    """One log record: severity, the logger (node) name, the message, the screen line."""

    stamp: float
    level: int
    node: str
    message: str
    text: str

    @property
    def level_name(self) -> str:
        return _NAMES.get(self.level, str(self.level))


def _level(value: str | int | None) -> int:
    if value is None:
        return 0
    if isinstance(value, int):
        return value
    key = value.strip().upper()
    key = 'WARN' if key == 'WARNING' else key
    if key not in LEVELS:
        raise GraphError(f'unknown log level {value!r}', fix=f'use one of {" ".join(LEVELS)}')
    return LEVELS[key]


def _render(lines: list[str]) -> str:
    """Colour each line by the severity tag it starts with (after a launch prefix)."""
    if not lines:
        return '<pre style="margin:0;color:#888">(no log records yet)</pre>'
    out = []
    for line in lines:
        found = re.search(r'\[(DEBUG|INFO|WARN|WARNING|ERROR|FATAL)\]', line)
        colour = _COLOURS.get(found.group(1).replace('WARNING', 'WARN'), '#24292f') \
            if found else '#24292f'
        out.append(f'<span style="color:{colour}">{html.escape(line)}</span>')
    return scroll_box('<pre style="margin:0;font-size:12px;line-height:1.35">'
                      f'{chr(10).join(out)}</pre>', '16em')


class Console:
    """Collects log records; `lines()` and the widget show those passing the filters."""

    def __init__(self, launch: LaunchHandle | None = None, rosout: bool | None = None,
                 level: str = 'INFO',
                 node: str | None = None, max_records: int = 5000,
                 domain_id: int | None = None) -> None:
        self.level = _level(level)
        self.node = node
        self.records: deque[LogRecord] = deque(maxlen=max_records)
        self.log = WidgetLog(max_lines=300, render=_render, hide_empty=False)
        self._lock = threading.Lock()
        self._options_lock = threading.Lock()
        self._closed = threading.Event()
        self._widget: Widget | None = None
        self._subscription: Subscription | None = None
        self._thread: threading.Thread | None = None
        self.launch = launch
        if rosout is None:
            rosout = launch is None  # a launch's output already holds its nodes' records
        if rosout:
            self._subscribe(domain_id)
        if launch is not None:
            self._thread = threading.Thread(target=self.log.guard(self._follow_launch),
                                            name='robot_lab-console', daemon=True)
            self._thread.start()
        owned_by_cell(self)

    # -- sources -----------------------------------------------------------------------
    def _subscribe(self, domain_id: int | None) -> None:
        from rcl_interfaces.msg import Log
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

        from robot_lab.rclpy_session import session

        self.session = session(domain_id)
        # /rosout publishers are reliable and transient-local (depth 1000): matching that
        # delivers the records a node logged before this console existed.
        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
        callback = self.log.guard(self._on_rosout)
        self._subscription = self.session.run_in_executor(
            lambda: self.session.node.create_subscription(Log, '/rosout', callback, qos))

    def _on_rosout(self, msg: Log) -> None:
        level = int.from_bytes(msg.level, 'little') if isinstance(msg.level, bytes) \
            else int(msg.level)
        stamp = msg.stamp.sec + msg.stamp.nanosec * 1e-9
        text = (f'[{_NAMES.get(level, level)}] [{msg.stamp.sec}.{msg.stamp.nanosec:09d}] '
                f'[{msg.name}]: {msg.msg}')
        self._add(LogRecord(stamp, level, msg.name, msg.msg, text))

    def _follow_launch(self) -> None:
        seen = 0
        launch = self.launch
        assert launch is not None  # this thread follows a launch
        output = launch.output
        while not self._closed.is_set():
            lines, seen = output.since(seen)
            for line in lines:
                level = _level(line.level) if line.level else LEVELS['INFO']
                node = line.logger or line.source
                self._add(LogRecord(line.time, level, node, line.text, line.text))
            if not lines and not launch.running:
                break
            output.wait(seen, 0.2)

    def _add(self, record: LogRecord) -> None:
        with self._lock:
            self.records.append(record)
            new_node = self._node_options is not None and record.node not in self._node_options
        if self._passes(record, self.level, self.node):
            self.log.writeline(record.text)
        if new_node:
            self._refresh_node_options()

    # -- filters -------------------------------------------------------------------------
    @staticmethod
    def _passes(record: LogRecord, level: int, node: str | None) -> bool:
        if record.level < level:
            return False
        return node is None or record.node.lstrip('/') == node.lstrip('/')

    def lines(self, level: str | None = None, node: str | None = None) -> list[str]:
        """Screen lines of the records passing `level`/`node` (default: the console's)."""
        minimum = self.level if level is None else _level(level)
        name = self.node if node is None else node
        with self._lock:
            return [r.text for r in self.records if self._passes(r, minimum, name)]

    def set_filter(self, level: str | None = None, node: str | None = '') -> None:
        """Change the filters (node=None shows all nodes); the view is rebuilt."""
        if level is not None:
            self.level = _level(level)
        if node != '':
            self.node = node
        self.log.clear()
        for line in self.lines():
            self.log.writeline(line)
        if self._widget is not None and self._node_box is not None:
            self._level_box.value = _NAMES.get(self.level, 'DEBUG')
            self._node_box.value = self.node or _ALL

    def wait_for(self, pattern: str, timeout: float = 10.0) -> LogRecord:
        """Block until a record's message matches `pattern` (regex); that record."""
        regex = re.compile(pattern)
        deadline = time.monotonic() + timeout
        while True:
            with self._lock:
                for record in self.records:
                    if regex.search(record.message):
                        return record
            if time.monotonic() >= deadline:
                raise GraphError(f'no log record matched {pattern!r} within {timeout:g} s',
                                 fix='is the node running and logging at that level?')
            self._closed.wait(0.05)

    def clear(self) -> None:
        with self._lock:
            self.records.clear()
        self.log.clear()

    # -- the widget ------------------------------------------------------------------------
    # Both stay None until the widget is whole: /rosout callbacks run on the session's
    # threads and may arrive while it is being built (they then skip the node list).
    _node_options: list[str] | None = None
    _node_box: Dropdown | None = None

    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import kit_box

            level_box = widgets.Dropdown(
                options=list(LEVELS), value=_NAMES.get(self.level, 'DEBUG'),
                description='level ≥', layout=widgets.Layout(width='14em'),
                style={'description_width': '4em'})
            node_box = widgets.Dropdown(options=[_ALL], value=_ALL, description='node',
                                        layout=widgets.Layout(width='20em'),
                                        style={'description_width': '3em'})
            clear = widgets.Button(description='Clear', icon='eraser',
                                   layout=widgets.Layout(width='7em'))
            level_box.observe(lambda c: self.set_filter(level=c['new']), names='value')
            node_box.observe(
                lambda c: self.set_filter(node=None if c['new'] == _ALL else c['new']),
                names='value')
            clear.on_click(lambda _b: self.clear())
            view = kit_box([widgets.HBox([level_box, node_box, clear]), self.log.widget])
            self._level_box = level_box
            with self._lock:
                self._node_box = node_box
                self._node_options = []
            self._widget = view
            self._refresh_node_options()
        return self._widget

    def _refresh_node_options(self) -> None:
        with self._options_lock:
            box = self._node_box
            if box is None:
                return
            with self._lock:
                nodes = sorted({r.node for r in self.records})
                self._node_options = nodes
            current = self.node or _ALL
            options = [_ALL, *nodes]
            if current not in options:
                options.append(current)
            box.options = options
            box.value = current

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            display(HTML(_render(self.lines()[-40:])))
        else:
            display(self.widget)

    def __repr__(self) -> str:
        return f'<Console {len(self.records)} records>'

    def close(self) -> None:
        self._closed.set()
        if self._subscription is not None:
            sub = self._subscription
            self.session.run_in_executor(lambda: self.session.node.destroy_subscription(sub))
            self._subscription = None
        if self._thread is not None:
            self._thread.join(timeout=2.0)


def console(launch: LaunchHandle | None = None, rosout: bool | None = None, level: str = 'INFO',
            node: str | None = None, domain_id: int | None = None) -> Console:
    """A log console: `robot_lab.console()` over /rosout, `console(handle)` over a launch."""
    return Console(launch=launch, rosout=rosout, level=level, node=node, domain_id=domain_id)
