"""The grader's observer waits for the graph before it counts (robot_lab.grading.package
.roles): a topic whose publisher is found after the nodes came up is waited for too, so
that a correct controller's commands are not counted from the middle of the window."""

from __future__ import annotations

import threading

import pytest

from robot_lab.grading.package import roles
from robot_lab.grading.package.roles import NodeSeen, Observation, TopicSeen


class _Graph:
    """Stands in for the observer's view of a live graph: what each refresh() finds.

    refresh number `publisher_at` finds the controller's /cmd_vel publisher, and number
    `sample_at` its first sample; /distance has delivered from the start."""

    def __init__(self, publisher_at: int, sample_at: int | None) -> None:
        self.lock = threading.Lock()
        self.obs = Observation()
        self.subs: dict[str, object] = {'/distance': object()}
        self.refreshes = 0
        self.publisher_at, self.sample_at = publisher_at, sample_at
        self.obs.nodes['/sensor'] = NodeSeen('/sensor', publishes=['/distance'])
        self.obs.nodes['/controller'] = NodeSeen('/controller', subscribes=['/distance'])
        self.obs.topics['/distance'] = TopicSeen('/distance', ['std_msgs/msg/Float32'],
                                                 publishers=['/sensor'], count=3)

    def refresh(self) -> list[str]:
        self.refreshes += 1
        if self.refreshes == self.publisher_at:
            self.obs.nodes['/controller'].publishes = ['/cmd_vel']
            self.obs.topics['/cmd_vel'] = TopicSeen('/cmd_vel', ['geometry_msgs/msg/Twist'],
                                                    publishers=['/controller'])
            self.subs['/cmd_vel'] = object()
        if self.refreshes == self.sample_at:
            self.obs.topics['/cmd_vel'].count = 1
        return list(self.obs.nodes)


def test_a_publisher_found_after_the_nodes_is_waited_for() -> None:
    graph = _Graph(publisher_at=3, sample_at=6)
    waited = roles._until_samples(graph)  # type: ignore[arg-type]
    assert graph.obs.topics['/cmd_vel'].count == 1, 'counted before /cmd_vel delivered'
    assert graph.refreshes >= 6
    assert waited >= roles._ENDPOINTS_STILL


def test_a_silent_publisher_ends_the_wait_at_its_deadline(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(roles, '_UNMATCHED', 1.5)
    graph = _Graph(publisher_at=2, sample_at=None)
    waited = roles._until_samples(graph)  # type: ignore[arg-type]
    assert graph.obs.topics['/cmd_vel'].count == 0
    assert 1.5 <= waited < 3.0
