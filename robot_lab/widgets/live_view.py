"""What every live view shares: one close, a PNG where no browser draws, showing itself.

A live view (plot, robot view, turtlesim window) feeds a browser-drawn canvas (`canvas.Feed`)
while a frontend shows it; with no frontend (nbval, CI, a static page) it collects for a
bounded time and shows a matplotlib picture instead. Closing stops the feed, says so on the
canvas and gives back what the view holds in ROS; the cell's next run closes it too.

Nothing here imports ipywidgets or anywidget: a headless run never pays for them.
"""

from __future__ import annotations

import io
import threading
import time
from typing import TYPE_CHECKING, ClassVar, Protocol, TypeVar

from robot_lab.widgets.output import WidgetLog, in_ci, is_headless

if TYPE_CHECKING:
    from IPython.display import Image
    from ipywidgets import Widget
    from matplotlib.figure import Figure

    from robot_lab.widgets.canvas import Feed

__all__ = ['LiveView', 'figure_png']

View = TypeVar('View', bound='LiveView')


class _Noted(Protocol):
    note: str  # the canvas's line under the drawing


def figure_png(fig: Figure) -> bytes:
    """A pyplot-free matplotlib Figure as PNG bytes (no global state, thread-safe)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format='png')
    return buffer.getvalue()


# A headless picture shows this many seconds of data (or what came by its deadline);
# how often the wait looks.
PICTURE_SPAN = 1.0
PICTURE_POLL = 0.05


class LiveView:
    """The base of the live views; a subclass draws `_figure()` and builds `widget`."""

    # At most this many seconds a headless run collects before its picture: (on a
    # desktop, in CI). It draws sooner once the view holds PICTURE_SPAN of data.
    headless_default: ClassVar[tuple[float, float]] = (3.0, 1.5)

    def __init__(self, rate: float, headless_seconds: float | None) -> None:
        self.rate = float(rate)
        self.headless_seconds = headless_seconds
        self.t0 = time.monotonic()
        self.log = WidgetLog(max_lines=20, height='5em')
        self._closed = threading.Event()
        self._widget: Widget | None = None
        self._canvas: _Noted | None = None
        self._feed: Feed | None = None

    @property
    def widget(self) -> Widget:
        raise NotImplementedError

    def start(self: View) -> View:
        """Show the live view: start sending new samples to the browser."""
        _ = self.widget
        if self._feed is not None:
            self._feed.start()
        return self

    # -- the static picture --------------------------------------------------------------
    def _figure(self) -> Figure:
        raise NotImplementedError

    def render_png(self) -> bytes:
        """The view now as a PNG (what a page without a live kernel shows)."""
        return figure_png(self._figure())

    def snapshot(self) -> Image:
        """An IPython Image of the view now (what a static page should show)."""
        from IPython.display import Image

        return Image(data=self.render_png(), format='png')

    def _headless_seconds(self) -> float:
        if self.headless_seconds is not None:
            return self.headless_seconds
        desktop, ci = self.headless_default
        return ci if in_ci() else desktop

    def _picture_ready(self) -> bool:
        """True once the view holds enough data for a picture worth looking at."""
        return False

    def _collect_headless(self) -> None:
        """Wait until the view has its picture (`_picture_ready`), at most until
        `headless_seconds` after creation. Waiting out the whole bound cost notebook 04's
        nbval run 3 s per view, where its plot had a second of every series after 1.2 s."""
        deadline = self.t0 + self._headless_seconds()
        while not self._picture_ready():
            left = deadline - time.monotonic()
            if left <= 0 or self._closed.wait(min(PICTURE_POLL, left)):
                return

    def _ipython_display_(self) -> None:
        from IPython.display import display

        if is_headless():
            self._collect_headless()
            display(self.snapshot())
        else:
            display(self.start().widget)

    # -- closing -------------------------------------------------------------------------
    def close(self) -> None:
        """Stop updating and unsubscribe (also done when the cell that made it runs again)."""
        if self._closed.is_set():
            return
        self._closed.set()
        if self._feed is not None:
            self._feed.close()
        self._release()

    def _release(self) -> None:
        """Say on the canvas that it stopped; a subclass also gives back its ROS entities."""
        if self._canvas is not None:
            self._canvas.note = 'closed: no longer updated'
