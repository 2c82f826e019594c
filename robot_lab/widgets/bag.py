"""A bag recorder and a bag player for the notebook: buttons over robot_lab.bag.

Each is a thin face over the library (`Recorder`, `Player`) and drivable from code
(`start()`/`stop()`, `play()`/`pause()`/`wait()`), so check cells, tests and nbval use
what students click. Live numbers are refreshed by a thread of the widget's own, and
every line the recorder or player logs goes into the widget's own log, never into
whichever cell happens to run next.
"""

from __future__ import annotations

import html
import threading
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from robot_lab.widgets.output import WidgetLog, is_headless

if TYPE_CHECKING:
    from ipywidgets import Widget

    from robot_lab.bag.play import Player
    from robot_lab.bag.record import Recorder

__all__ = ['BagPlayer', 'BagRecorder', 'player', 'recorder']

_REFRESH = 0.25


def _counts_html(counts: dict[str, int], types: dict[str, str] | None = None) -> str:
    if not counts:
        return '<span style="color:#666">no topic subscribed yet</span>'
    rows = ''.join(
        f'<tr><td><code>{html.escape(t)}</code></td>'
        f'<td style="color:#666">{html.escape((types or {}).get(t, ""))}</td>'
        f'<td style="text-align:right"><b>{n}</b></td></tr>'
        for t, n in counts.items()
    )
    return f'<table style="font-size:13px">{rows}</table>'


class _Refresher:
    """Calls `refresh` a few times a second on a daemon thread while `active()` is true."""

    def __init__(self, log: WidgetLog, refresh: Callable[[], None], active: Callable[[], bool],
                 name: str) -> None:
        self._log = log
        self._refresh = refresh
        self._active = active
        self._name = name
        self._thread: threading.Thread | None = None

    def kick(self) -> None:
        if self._thread is not None and self._thread.is_alive():
            return
        self._thread = threading.Thread(
            target=self._log.guard(self._run), name=self._name, daemon=True
        )
        self._thread.start()

    def _run(self) -> None:
        stop = threading.Event()
        while self._active():
            self._refresh()
            stop.wait(_REFRESH)
        self._refresh()


class BagRecorder:
    """Start/stop recording topics into a bag; shows elapsed time and live per-topic counts."""

    def __init__(
        self,
        topics: Iterable[str] = (),
        *,
        all_topics: bool = False,
        output: str | Path | None = None,
        storage: str = 'mcap',
        domain_id: int | None = None,
    ) -> None:
        self.topics = list(topics)
        self.all_topics = all_topics
        self.output = output
        self.storage = storage
        self.domain_id = domain_id
        self.recording: Recorder | None = None  # of the current/last take
        self.bags: list[Path] = []
        self.log = WidgetLog(max_lines=50, height='6em')
        self._widget: Widget | None = None
        self._refresher = _Refresher(self.log, self.refresh, lambda: self.running,
                                     'robot_lab-bag-recorder-widget')

    @property
    def running(self) -> bool:
        return self.recording is not None and self.recording.running

    @property
    def counts(self) -> dict[str, int]:
        return dict(self.recording.counts) if self.recording is not None else {}

    @property
    def elapsed(self) -> float:
        return self.recording.elapsed if self.recording is not None else 0.0

    @property
    def path(self) -> Path | None:
        return self.recording.path if self.recording is not None else None

    def start(self) -> Recorder:
        """Start a new recording (a new bag folder each time); returns the Recorder."""
        from robot_lab.bag.record import Recorder

        recording = self.recording
        if recording is not None and recording.running:
            return recording
        output = self.output
        if output is not None and self.bags:
            output = f'{output}_{len(self.bags)}'  # a second take must not reuse the folder
        self.recording = Recorder(
            self.topics, all_topics=self.all_topics, output=output, storage=self.storage,
            domain_id=self.domain_id, log=self.log.writeline,
        )
        self.recording.start()
        self.bags.append(self.recording.path)
        self.refresh()
        self._refresher.kick()
        return self.recording

    def stop(self) -> Path | None:
        """Stop and close the bag; returns its folder (None if nothing was recording)."""
        if self.recording is None:
            return None
        path: Path = self.recording.stop()
        self.refresh()
        return path

    def status_html(self) -> str:
        if self.recording is None:
            return '<span style="color:#666">not recording</span>'
        state = 'recording' if self.running else 'stopped'
        colour = '#c62828' if self.running else '#666'
        head = (f'<span style="color:{colour}">●</span> {state} '
                f'<code>{html.escape(str(self.recording.path))}</code> — '
                f'{self.elapsed:.1f} s, {self.recording.total} messages')
        return head + _counts_html(self.counts, self.recording.types)

    def refresh(self) -> None:
        if self._widget is None:
            return
        self._status.value = self.status_html()
        self._start_button.disabled = self.running
        self._stop_button.disabled = not self.running

    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import kit_box

            self._start_button = widgets.Button(description='Record', icon='circle',
                                                button_style='danger')
            self._stop_button = widgets.Button(description='Stop', icon='stop')
            self._start_button.on_click(self.log.guard(lambda _b: self.start()))
            self._stop_button.on_click(self.log.guard(lambda _b: self.stop()))
            self._status = widgets.HTML()
            what = 'all topics' if self.all_topics else ' '.join(self.topics)
            header = widgets.HTML(f'<b>bag record</b> <code>{html.escape(what)}</code>')
            self._widget = kit_box([
                header, widgets.HBox([self._start_button, self._stop_button]),
                self._status, self.log.widget,
            ])
            self.refresh()
        return self._widget

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            display(HTML(self.status_html()))
        else:
            display(self.widget)

    def __repr__(self) -> str:
        state = 'recording' if self.running else 'idle'
        return f'<BagRecorder {state} {self.path or ""} {self.counts}>'


class BagPlayer:
    """Play/pause a bag, change the rate while playing, and watch a progress bar."""

    def __init__(
        self,
        bag: str | Path,
        *,
        rate: float = 1.0,
        loop: bool = False,
        topics: Iterable[str] | None = None,
        domain_id: int | None = None,
    ) -> None:
        self.bag = Path(bag)
        self._rate = rate
        self.loop = loop
        self.topics = None if topics is None else list(topics)
        self.domain_id = domain_id
        self.playback: Player | None = None  # of the current/last run
        self.log = WidgetLog(max_lines=50, height='5em')
        self._widget: Widget | None = None
        self._refresher = _Refresher(self.log, self.refresh, lambda: self.running,
                                     'robot_lab-bag-player-widget')

    @property
    def running(self) -> bool:
        return self.playback is not None and self.playback.running

    @property
    def paused(self) -> bool:
        return self.playback is not None and self.playback.paused

    @property
    def progress(self) -> float:
        return self.playback.progress if self.playback is not None else 0.0

    @property
    def rate(self) -> float:
        return self._rate

    def play(self) -> Player:
        """Resume if paused; otherwise start from the beginning. Returns the Player."""
        from robot_lab.bag.play import Player

        playback = self.playback
        if playback is not None and self.running:
            playback.resume()
        else:
            playback = self.playback = Player(
                self.bag, rate=self._rate, loop=self.loop, topics=self.topics,
                domain_id=self.domain_id, log=self.log.writeline,
            )
            playback.start()
        self.refresh()
        self._refresher.kick()
        return playback

    def pause(self) -> None:
        if self.playback is not None:
            self.playback.pause()
        self.refresh()

    def toggle(self) -> None:
        if self.running and not self.paused:
            self.pause()
        else:
            self.play()

    def stop(self) -> None:
        if self.playback is not None:
            self.playback.stop()
        self.refresh()

    def set_rate(self, rate: float) -> None:
        self._rate = float(rate)
        if self.playback is not None and self.running:
            self.playback.set_rate(rate)
        if self._widget is not None and self._rate_box.value != self._rate:
            self._rate_box.value = self._rate

    def wait(self, timeout: float | None = None) -> bool:
        """Block until playback has finished (True) or `timeout` passed (False)."""
        if self.playback is None:
            return True
        done: bool = self.playback.wait(timeout)
        self.refresh()
        return done

    def status_text(self) -> str:
        if self.playback is None:
            return f'{self.bag.name}: not started'
        p = self.playback
        state = 'paused' if p.paused else 'playing' if p.running else 'finished'
        return (f'{self.bag.name}: {state}, {p.played}/{p.total} messages, '
                f'{p.position:.1f} s, {100 * p.progress:.0f} %, rate {p.rate:g}')

    def refresh(self) -> None:
        if self._widget is None:
            return
        self._progress.value = self.progress
        self._status.value = html.escape(self.status_text())
        playing = self.running and not self.paused
        self._play_button.description = 'Pause' if playing else 'Play'
        self._play_button.icon = 'pause' if playing else 'play'
        self._stop_button.disabled = not self.running

    @property
    def widget(self) -> Widget:
        if self._widget is None:
            import ipywidgets as widgets

            from robot_lab.widgets.canvas import kit_box

            self._play_button = widgets.Button(description='Play', icon='play',
                                               button_style='success')
            self._stop_button = widgets.Button(description='Stop', icon='stop')
            self._play_button.on_click(self.log.guard(lambda _b: self.toggle()))
            self._stop_button.on_click(self.log.guard(lambda _b: self.stop()))
            self._rate_box = widgets.BoundedFloatText(
                value=self._rate, min=0.05, max=20.0, step=0.25, description='rate',
                layout=widgets.Layout(width='10em'),
            )
            self._rate_box.observe(
                self.log.guard(lambda change: self.set_rate(change['new'])), names='value'
            )
            self._progress = widgets.FloatProgress(value=0.0, min=0.0, max=1.0,
                                                   layout=widgets.Layout(width='100%'))
            self._status = widgets.HTML()
            header = widgets.HTML(
                f'<b>bag play</b> <code>{html.escape(str(self.bag))}</code>')
            self._widget = kit_box([
                header,
                widgets.HBox([self._play_button, self._stop_button, self._rate_box]),
                self._progress, self._status, self.log.widget,
            ])
            self.refresh()
        return self._widget

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        if is_headless():
            display(HTML(html.escape(self.status_text())))
        else:
            display(self.widget)

    def __repr__(self) -> str:
        return f'<BagPlayer {self.status_text()}>'


def recorder(
    *topics: str,
    all_topics: bool = False,
    output: str | Path | None = None,
    storage: str = 'mcap',
    domain_id: int | None = None,
) -> BagRecorder:
    """A record button for `topics` (or all): `rec = recorder('/sensor/temperature'); rec`."""
    return BagRecorder(topics, all_topics=all_topics, output=output, storage=storage,
                       domain_id=domain_id)


def player(
    bag: str | Path,
    *,
    rate: float = 1.0,
    loop: bool = False,
    topics: Iterable[str] | None = None,
    domain_id: int | None = None,
) -> BagPlayer:
    """Play/pause, rate and progress for a bag (folder or .mcap/.db3 file)."""
    return BagPlayer(bag, rate=rate, loop=loop, topics=topics, domain_id=domain_id)
