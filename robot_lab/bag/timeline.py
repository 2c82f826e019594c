"""The bag's own clock during playback: which bag instant is "now" under pause, resume,
rate changes and single steps, and the wait until a message is due.

The thread that plays and the one that controls playback (keys, widget buttons) share
this state under one condition; apart from the player, the timing rules read in one place.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Literal

__all__ = ['Timeline']


class Timeline:
    """Bag time anchored at the last start/resume/rate change, so pause, resume and rate
    changes are exact. `cond` guards every field; `stopped` wakes every waiter."""

    def __init__(self, rate: float, paused: bool, log: Callable[[str, str], None]) -> None:
        self.cond = threading.Condition()
        self.rate = rate
        self.paused = paused  # rosbag2's -p/--start-paused
        self.steps = 0  # play_next() calls the playing thread has not served yet
        self.stopped = False
        self.anchor_wall = 0.0
        self.anchor_bag = 0
        self._log = log

    def now(self) -> int:
        """The bag time now, in ns (the caller holds `cond`)."""
        if self.paused:
            return self.anchor_bag
        return self.anchor_bag + int((time.monotonic() - self.anchor_wall) * self.rate * 1e9)

    def start_at(self, first: int) -> None:
        """Bag time `first` is now."""
        with self.cond:
            self.anchor_bag = first
            self.anchor_wall = time.monotonic()

    def pause(self) -> None:
        with self.cond:
            if not self.paused:
                self.anchor_bag = self.now()
                self.paused = True
                self._log('INFO', 'Pausing play.')
            self.cond.notify_all()

    def resume(self) -> None:
        with self.cond:
            if self.paused:
                self.anchor_wall = time.monotonic()
                self.paused = False
                self._log('INFO', 'Resuming play.')
            self.cond.notify_all()

    def request_next(self) -> bool:
        """While paused, one more message may go out at once; False when not paused."""
        with self.cond:
            if not self.paused:
                self._log('WARN', 'Called play next, but not in paused state.')
                return False
            self.steps += 1
            self.cond.notify_all()
            return True

    def set_rate(self, rate: float) -> bool:
        if rate <= 0:
            self._log('WARN', f'Failed to set rate to invalid value {rate}')
            return False
        with self.cond:
            self.anchor_bag = self.now()
            self.anchor_wall = time.monotonic()
            self.rate = float(rate)
            self.cond.notify_all()
        self._log('INFO', f'Set rate to {rate:g}')
        return True

    def wait_until(self, stamp: int) -> Literal['due', 'step'] | None:
        """Sleep until bag time `stamp` is due ('due'), or a play_next() call releases it
        while paused ('step'); None if stopped meanwhile."""
        with self.cond:
            while not self.stopped:
                if self.paused:
                    if self.steps:
                        self.steps -= 1
                        self.anchor_bag = max(self.anchor_bag, stamp)  # the clock jumps
                        return 'step'
                    self.cond.wait()
                    continue
                remaining = (stamp - self.now()) / 1e9 / self.rate
                if remaining <= 0:
                    return 'due'
                self.cond.wait(remaining)
            return None
