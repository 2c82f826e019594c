"""Discovery's settling rules (graph/settler.py) without DDS: a clock that moves only when
the settler sleeps, and conditions scripted against it."""

from __future__ import annotations

import threading
from collections.abc import Callable

import pytest

from robot_lab.graph.settler import HostPorts, Outcome, Rules, RunClock, Settler

RULES = Rules()


class Clock:
    """Monotonic time that passes only in sleep()."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += seconds


def settle(*, young: bool = True, everyone: Callable[[float], bool | None] = lambda t: True,
           ready: Callable[[float], bool | None] = lambda t: None,
           heard: Callable[[float], bool] = lambda t: False,
           pending: Callable[[float], bool] = lambda t: False,
           drops: Callable[[float], int] = lambda t: 0,
           probe: Callable[[float], object] = lambda t: 'answer',
           timeout: float = 2.0, ready_settle: float = 0.05) -> tuple[Outcome[object], list[str]]:
    """Run a settler whose conditions are functions of the seconds since it began; the
    outcome and the order of the first poll's reads."""
    clock = Clock()
    created = clock.now - (0.1 if young else 60.0)
    settler = Settler(monotonic=clock, sleep=clock.sleep)
    began = clock.now
    order: list[str] = []

    def at(name: str, function: Callable[[float], object]) -> Callable[[], object]:
        def read() -> object:
            if len(order) < 5:
                order.append(name)
            return function(clock.now - began)
        return read

    outcome = settler.settle(
        at('probe', probe), created=created, rules=RULES, timeout=timeout, settle=RULES.settle,
        ready=at('ready', ready), ready_settle=ready_settle,  # type: ignore[arg-type]
        complete=at('complete', everyone), heard=at('heard', heard),  # type: ignore[arg-type]
        pending=at('pending', pending), drops=at('drops', drops))  # type: ignore[arg-type]
    return outcome, order


def test_every_participant_seen_and_a_stable_answer_is_complete() -> None:
    outcome, order = settle()
    assert outcome.complete and outcome.value == 'answer'
    assert RULES.settle <= outcome.waited < RULES.settle + 0.05
    assert order.index('probe') > order.index('complete')  # the answer is read last


def test_a_warm_session_settles_sooner() -> None:
    outcome, _ = settle(young=False)
    assert outcome.complete and outcome.waited < RULES.warm_settle + 0.05


def test_a_session_is_young_by_its_own_created_at_each_query() -> None:
    """The settler keeps no copy of when its session was made: a session made young
    again (a cold command's, in a test) is young at its next query on the same settler."""
    clock = Clock()
    settler = Settler(monotonic=clock, sleep=clock.sleep)

    def query(created: float) -> Outcome[str]:
        return settler.settle(lambda: 'answer', created=created, rules=RULES, timeout=2.0,
                              settle=RULES.settle, ready=lambda: None, ready_settle=0.05,
                              complete=lambda: True, heard=lambda: False,
                              pending=lambda: False, drops=lambda: 0)

    assert not query(clock.now - 60.0).young
    assert query(clock.now).young
    assert not query(clock.now - RULES.warm_age).young


def test_a_changing_answer_is_waited_out() -> None:
    outcome, _ = settle(probe=lambda t: round(t, 2) if t < 1.0 else 'still')
    assert outcome.complete and outcome.value == 'still'
    assert 1.0 + RULES.settle <= outcome.waited < 1.0 + RULES.settle + 0.05


def test_a_participant_not_seen_holds_the_answer_to_its_deadline() -> None:
    young, _ = settle(everyone=lambda t: False)
    assert not young.complete and young.everyone is False
    assert young.waited == pytest.approx(RULES.participant_timeout, abs=0.03)
    warm, _ = settle(young=False, everyone=lambda t: False)
    assert warm.waited == pytest.approx(RULES.warm_participant_timeout, abs=0.03)


def test_a_participant_seen_late_ends_the_wait_then() -> None:
    outcome, _ = settle(everyone=lambda t: t >= 3.0)
    assert outcome.complete  # the answer has stood still all along: at once
    assert 3.0 <= outcome.waited < 3.05


def test_nodes_on_their_way_hold_a_complete_graph() -> None:
    expected, _ = settle(ready=lambda t: False)
    assert not expected.complete
    assert expected.waited == pytest.approx(RULES.expected_timeout, abs=0.03)
    named, _ = settle(ready=lambda t: False, pending=lambda t: True)
    assert named.waited == pytest.approx(RULES.names_timeout, abs=0.03)
    arrived, _ = settle(ready=lambda t: t >= 1.0)
    assert arrived.complete and 1.0 <= arrived.waited < 1.0 + RULES.settle


def test_without_a_count_a_young_session_waits_for_a_burst_of_answers() -> None:
    outcome, _ = settle(everyone=lambda t: None, heard=lambda t: t >= 1.0)
    assert outcome.complete
    assert 1.0 + RULES.answer_burst <= outcome.waited < 1.0 + RULES.answer_burst + 0.05
    nobody, _ = settle(everyone=lambda t: None)
    assert not nobody.complete  # never complete on the session's age alone
    warm, _ = settle(young=False, everyone=lambda t: None)
    assert warm.complete and warm.waited < 0.1


def test_lost_datagrams_hold_a_young_answer_for_their_resend() -> None:
    outcome, _ = settle(drops=lambda t: 3)
    assert outcome.complete and outcome.lost == 3
    assert RULES.settle + RULES.resend_wait <= outcome.waited < (
        RULES.settle + RULES.resend_wait + 0.05)
    warm, _ = settle(young=False, drops=lambda t: 3)
    assert warm.lost == 0 and warm.waited < 0.1  # a warm session does not look


def test_a_poll_the_host_did_not_run_counts_as_one_gap() -> None:
    clock = Clock()
    run = RunClock(RULES.max_poll_gap, clock)
    clock.sleep(30.0)  # the process was not run
    assert run() == RULES.max_poll_gap
    clock.sleep(0.1)
    assert run() == pytest.approx(RULES.max_poll_gap + 0.1)


def test_a_node_without_endpoints_holds_queries_once_per_session() -> None:
    clock = Clock()
    settler = Settler(monotonic=clock, sleep=clock.sleep)
    assert not settler.bare_long_enough({'/cached'}, 3.0)
    clock.sleep(3.0)
    assert settler.bare_long_enough({'/cached'}, 3.0)  # the next query: no wait again
    assert settler.bare_long_enough(set(), 3.0)
    assert not settler.bare_long_enough({'/cached'}, 3.0)  # gone and back: counted anew


def test_bare_nodes_of_threads_sharing_a_session_are_kept_whole() -> None:
    """A graph daemon's client threads share one session's settler."""
    clock = Clock()
    settler = Settler(monotonic=clock, sleep=clock.sleep)
    names = {f'/n{i}' for i in range(50)}
    threads = [threading.Thread(target=lambda: [settler.bare_long_enough(names, 1.0)
                                                for _ in range(200)]) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    clock.sleep(1.0)
    assert settler.bare_long_enough(names, 1.0)


def test_host_ports_count_only_once_this_process_holds_one() -> None:
    table = {7410: 11, 7412: 12}
    own: set[int] = set()
    ports = HostPorts(lambda domain: dict(table), lambda: own)
    assert ports(0) is None  # another RMW or profile: the count would mean nothing
    own.add(12)
    assert ports(0) == table
    own.clear()
    assert ports(0) == table  # found once: kept
    assert ports(1) is None  # per domain
