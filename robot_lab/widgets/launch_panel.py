"""A launch file as a panel: start and stop buttons, one status light per process, its output.

The panel is a thin face over `robot_lab.launch(...)`: Start is that call, Stop is
`handle.shutdown()`, and the lights are `handle.processes` polled twice a second on a
thread of the panel's own (so the kernel stays free and nothing prints into other cells).
"""

from __future__ import annotations

import html
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from robot_lab.widgets.console import Console
from robot_lab.widgets.output import WidgetLog, is_headless, owned_by_cell

if TYPE_CHECKING:
    from ipywidgets import Widget

    from robot_lab.launch.api import LaunchHandle

__all__ = ['LaunchPanel', 'launch_panel']

_LIGHTS = {'running': '#2e7d32', 'respawning': '#f9a825', 'finished': '#9e9e9e',
           'died': '#c62828', 'pending': '#90caf9'}


def _light(state: str) -> str:
    colour = _LIGHTS.get(state, '#9e9e9e')
    return (f'<span style="display:inline-block;width:0.9em;height:0.9em;border-radius:50%;'
            f'background:{colour};vertical-align:middle" title="{html.escape(state)}"></span>')


class LaunchPanel:
    """Start/stop one launch file and watch its processes; drivable with start()/stop()."""

    def __init__(self, pkg_or_path: str | Path, file: str | None = None, **args: object) -> None:
        self.source = pkg_or_path
        self.file = file
        self.args = args
        self.handle: LaunchHandle | None = None
        self.console: Console | None = None
        self.log = WidgetLog(max_lines=20, height='5em')
        self._widget: Widget | None = None
        self._closed = threading.Event()
        self._poller: threading.Thread | None = None
        owned_by_cell(self)

    @property
    def title(self) -> str:
        parts = [str(self.source)] + ([self.file] if self.file else [])
        parts += [f'{k}:={v}' for k, v in self.args.items()]
        return ' '.join(parts)

    def start(self) -> LaunchHandle:
        """Launch (a running one is replaced, as a re-run launch cell does); the handle."""
        from robot_lab.launch.api import launch

        self.stop()
        self.handle = launch(self.source, self.file, **self.args)
        self.console = Console(launch=self.handle, level='DEBUG')
        if self._widget is not None:
            self._output.children = [self.console.widget]
        self.refresh()
        return self.handle

    def stop(self) -> None:
        """Shut the launch down (SIGINT, then SIGTERM, then SIGKILL) and wait for the end."""
        if self.handle is not None:
            self.handle.shutdown()
        if self.console is not None:
            self.console.close()
        self.refresh()

    @property
    def states(self) -> dict[str, str]:
        """Process label -> state ('running', 'died', ...); empty before start()."""
        if self.handle is None:
            return {}
        return {p.label: p.state for p in self.handle.processes}

    def status_html(self) -> str:
        if self.handle is None:
            return '<span style="color:#666">not started</span>'
        rows = []
        for p in self.handle.processes:
            code = '' if p.exit_code is None else f' (exit code {p.exit_code})'
            pid = '' if p.pid is None else f' pid {p.pid}'
            detail = f'{html.escape(p.state)}{pid}{code}'
            rows.append(f'<div style="line-height:1.6">{_light(p.state)}&nbsp;'
                        f'<code>{html.escape(p.label)}</code> {html.escape(p.name)}'
                        f'<span style="color:#666"> — {detail}</span></div>')
        return ''.join(rows) or '<span style="color:#666">no processes</span>'

    def refresh(self) -> None:
        if self._widget is not None:
            self._status.value = self.status_html()
            running = self.handle is not None and self.handle.running
            self._start_button.disabled = running
            self._stop_button.disabled = not running

    # -- the widget ------------------------------------------------------------------------
    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import kit_box

            self._start_button = widgets.Button(description='Start', icon='play',
                                                button_style='success')
            self._stop_button = widgets.Button(description='Stop', icon='stop',
                                               button_style='danger')
            self._start_button.on_click(self.log.guard(lambda _b: self.start()))
            self._stop_button.on_click(self.log.guard(lambda _b: self.stop()))
            self._status = widgets.HTML()
            self._output = widgets.Box(
                [self.console.widget] if self.console is not None else [])
            header = widgets.HTML(f'<b>launch</b> <code>{html.escape(self.title)}</code>')
            self._widget = kit_box([
                header, widgets.HBox([self._start_button, self._stop_button]),
                self._status, self._output, self.log.widget])
            self.refresh()
            self._poller = threading.Thread(target=self.log.guard(self._poll),
                                            name='robot_lab-launch-panel', daemon=True)
            self._poller.start()
        return self._widget

    def _poll(self) -> None:
        while not self._closed.wait(0.5):
            self.refresh()

    def close(self) -> None:
        """Stop polling (the launch keeps running; stop() ends it)."""
        self._closed.set()

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            title = f'<b>launch</b> <code>{html.escape(self.title)}</code><br>'
            display(HTML(title + self.status_html()))
        else:
            display(self.widget)

    def __repr__(self) -> str:
        return f'<LaunchPanel {self.title}: {self.states or "not started"}>'


def launch_panel(pkg_or_path: str | Path, file: str | None = None, start: bool = False,
                 **args: object) -> LaunchPanel:
    """Buttons and status lights for a launch file: `robot_lab.launch_panel('robot_lab',
    'robot.launch.xml', robot_name='robot_alpha')`; `start=True` launches at once."""
    panel = LaunchPanel(pkg_or_path, file, **args)
    if start:
        panel.start()
    return panel
