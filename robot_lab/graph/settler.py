"""When a session's graph has settled, as an object: the rules of graph/discovery.py's
`settled()` (read its constants for why each wait is as long as it is), with what they
depend on passed in, so they can be tested without DDS.

A `Settler` belongs to one session and keeps what that session has learnt between queries
(since when it lists a node without endpoints) under its own lock: a graph daemon answers
each client in a thread of its own over one session. Its clock (a monotonic clock and a
sleep) is injected, and so is `HostPorts`, the host's socket table of discovery ports.
Nothing here imports rclpy.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Generic, TypeVar

__all__ = ['HostPorts', 'Outcome', 'Rules', 'RunClock', 'Settler']

T = TypeVar('T')


@dataclass(frozen=True)
class Rules:
    """The waits (seconds) of `Settler.settle`; discovery.py documents each."""

    settle: float = 0.25
    warm_age: float = 1.5
    warm_settle: float = 0.05
    answer_burst: float = 0.45
    expected_timeout: float = 5.0
    names_timeout: float = 12.0
    participant_timeout: float = 10.0
    warm_participant_timeout: float = 7.0
    resend_wait: float = 1.5
    max_poll_gap: float = 0.25
    poll: float = 0.02


class RunClock:
    """Seconds since it was made, each gap between two readings counted at most
    `max_gap`: the time this process had to see discovery progress (a poll that comes
    later than that after the one before was not run; discovery made no progress then
    either)."""

    def __init__(self, max_gap: float, monotonic: Callable[[], float] = time.monotonic) -> None:
        self._monotonic = monotonic
        self._max_gap = max_gap
        self._last = monotonic()
        self._elapsed = 0.0

    def __call__(self) -> float:
        now = self._monotonic()
        self._elapsed += min(now - self._last, self._max_gap)
        self._last = now
        return self._elapsed


class HostPorts:
    """The domain's bound discovery ports (port -> socket inode) when they can be counted,
    else None: only once this process's own port is among them (another RMW, a profile
    with other ports: the count would mean nothing). Only a yes is kept: this process's
    port, once found, stays its own. `table(domain)` reads the socket table, `own()` the
    inodes of this process's sockets."""

    def __init__(self, table: Callable[[int], dict[int, int]],
                 own: Callable[[], set[int]]) -> None:
        self._table = table
        self._own = own
        self._lock = threading.Lock()
        self._found: set[int] = set()  # domains in which this process's port was found

    def __call__(self, domain_id: int) -> dict[int, int] | None:
        ports = self._table(domain_id)
        with self._lock:
            if domain_id in self._found:
                return ports
        if not self._own() & set(ports.values()):
            return None
        with self._lock:
            self._found.add(domain_id)
        return ports


@dataclass
class Outcome(Generic[T]):
    """How `settle` answered: the answer, whether the graph was complete (else a deadline
    passed), and what the last poll saw (for the note and the debug line)."""

    value: T
    complete: bool
    waited: float  # run-clock seconds
    young: bool
    everyone: bool | None
    expectation: bool | None
    lost: int


class Settler:
    """One session's settling (see the module's docstring)."""

    def __init__(self, created: float, *, monotonic: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.created = created
        self.monotonic = monotonic
        self.sleep = sleep
        self._lock = threading.Lock()
        self._bare_since: dict[str, float] = {}

    def bare_long_enough(self, bare: Iterable[str], wait: float) -> bool:
        """Whether every node listed without endpoints (`bare`) has been so for `wait`:
        a node whose endpoints never come (a name a graph cache kept) holds one query for
        that long, and this session's later queries not at all."""
        now = self.monotonic()
        with self._lock:
            since = {name: self._bare_since.get(name, now) for name in bare}
            self._bare_since = since
        return all(now - first >= wait for first in since.values())

    def settle(self, probe: Callable[[], T], *, rules: Rules, timeout: float, settle: float,
               ready: Callable[[], bool | None], ready_settle: float,
               complete: Callable[[], bool | None], heard: Callable[[], bool],
               pending: Callable[[], bool], drops: Callable[[], int]) -> Outcome[T]:
        """`probe()` once the graph is complete and the answer stopped changing, or at the
        deadline (discovery.settled says which condition does what)."""
        young = self.monotonic() - self.created < rules.warm_age
        clock, start = RunClock(rules.max_poll_gap, self.monotonic), 0.0
        if not young:
            settle = min(settle, rules.warm_settle)
        heard_at: float | None = None
        lost, lost_at = 0, 0.0
        value: T | None = None
        changed = start
        while True:
            # Every condition is read before the answer: the graph only grows while
            # discovery settles, so an answer read after them holds all they saw. The other
            # way round, the whole graph can arrive between the two reads (this process not
            # run for a moment while its DDS threads were): a cold `node list` on a CI host
            # printed no node at all, the graph complete and the answer from before it.
            now = clock()
            expectation = ready()
            everyone = complete()
            heard_now = heard() if everyone is None and young else False
            waiting_names = expectation is False and pending()
            fresh = probe()
            if value is None or fresh != value:
                value, changed = fresh, now
            deadline = start + timeout
            if everyone is not None:
                # Every participant on the host is seen with its nodes' endpoints: complete,
                # however young the session and however slow the others were to answer.
                old_enough = everyone
                if not everyone:
                    deadline = start + max(timeout, rules.participant_timeout if young
                                           else rules.warm_participant_timeout)
            elif young:
                # No count to go by: answer once the others have answered (a whole burst)
                # and every node listed has its endpoints; never on the session's age alone.
                if heard_at is None and heard_now:
                    heard_at = now
                old_enough = (heard_at is not None and now - heard_at >= rules.answer_burst
                              and heard_now)
            else:
                old_enough = True
            if expectation is True:
                # Every announced node is seen; a young session still waits for the others'
                # answers, since a node nobody announced (a kernel's) may not be heard yet.
                settle = min(settle, ready_settle)
            elif expectation is False:
                # Nodes are on their way: a quiet graph is not a complete one yet.
                wait = rules.names_timeout if waiting_names else rules.expected_timeout
                old_enough, deadline = False, max(deadline, start + wait)
            if young and old_enough and now - changed >= settle:
                dropped = drops()
                if dropped > lost:
                    lost, lost_at = dropped, now
                if lost and now - lost_at < rules.resend_wait:
                    old_enough = False  # a lost announcement is on its way again
                    deadline = max(deadline, min(lost_at + rules.resend_wait + settle,
                                                 start + rules.participant_timeout))
            if (old_enough and now - changed >= settle) or now >= deadline:
                return Outcome(fresh, old_enough, now, young, everyone, expectation, lost)
            self.sleep(rules.poll)
