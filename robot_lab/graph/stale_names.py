"""Node names a long-lived graph keeps after their node is gone, and which to drop."""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping

__all__ = ['STALE_AFTER', 'StaleNames']

# How long a node name may be listed more often than it has endpoints before the daemon
# calls the extra entries stale: a node just discovered has its name a moment before its
# endpoints, a node that left takes its endpoints with it.
STALE_AFTER = 2.5


class StaleNames:
    """Drops node names that stay in a long-lived graph after their node is gone.

    rmw keeps node names per participant from `ros_discovery_info` messages; a message
    taken after its participant was removed brings the participant back with its nodes,
    and nothing removes it again (ros2/ros2#1413: `ros2 node list` through the daemon
    listed /robot and /sensor for 10+ minutes after notebook 06, twice after the next
    launch, while `--no-daemon` was right). Endpoints leave with their participant, so a
    name listed more times than it has /parameter_events or /rosout publishers, for longer
    than STALE_AFTER, is listed only as often as it has them. A fresh session (no daemon)
    cannot hold such entries and is not filtered.

    Each name keeps the ages of its entries without endpoints, oldest first: an entry that
    gains endpoints is the newest one (a node just discovered), an entry that leaves the
    list is the oldest (a ghost that went). So the next launch of the same nodes beside
    old ghosts is listed at once, each name once, before its endpoints arrive.
    """

    def __init__(self, stale_after: float = STALE_AFTER) -> None:
        self.stale_after = stale_after
        self._waiting: dict[str, list[float]] = {}  # name -> since when, per extra entry
        self._live: dict[str, int] = {}
        self._lock = threading.Lock()

    def audit(self, listed: list[str], live: Mapping[str, int],
              now: float | None = None) -> None:
        """Note which names are listed more often than they have endpoints, since when."""
        now = time.monotonic() if now is None else now
        counts: dict[str, int] = {}
        for name in listed:
            counts[name] = counts.get(name, 0) + 1
        with self._lock:
            for name in set(counts) | set(self._waiting):
                extra = max(0, counts.get(name, 0) - live.get(name, 0))
                waiting = self._waiting.get(name, [])
                gained = live.get(name, 0) > self._live.get(name, 0)
                while len(waiting) > extra:  # endpoints came (newest) or an entry went
                    waiting.pop(-1 if gained else 0)
                waiting.extend([now] * (extra - len(waiting)))
                if waiting:
                    self._waiting[name] = waiting
                else:
                    self._waiting.pop(name, None)
            self._live = {name: live.get(name, 0) for name in counts}

    def filter(self, listed: list[str], live: Mapping[str, int],
               now: float | None = None) -> list[str]:
        """`listed` without the entries that have been stale for STALE_AFTER."""
        now = time.monotonic() if now is None else now
        self.audit(listed, live, now)
        with self._lock:
            hidden = {name: sum(now - since >= self.stale_after for since in waiting)
                      for name, waiting in self._waiting.items()}
        shown = {name: listed.count(name) - hidden.get(name, 0) for name in set(listed)}
        kept: list[str] = []
        for name in listed:
            if kept.count(name) < shown[name]:
                kept.append(name)
        return kept
