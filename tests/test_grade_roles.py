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


def test_a_launched_process_sharing_pid_bits_with_a_heard_one_is_waited_for(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Where pid_max exceeds 65536, the watch's end (roles._unheard) must not take a heard
    participant of process 4464 for launched process 70000 (equal mod 65536)."""
    from types import SimpleNamespace

    from robot_lab.graph import discovery, host_sockets

    def info(pid: int) -> SimpleNamespace:
        prefix = b'\x01\x0f\x00\x00' + pid.to_bytes(2, 'little') + bytes(6)
        return SimpleNamespace(node_name='n', node_namespace='/', endpoint_gid=prefix + bytes(4))

    sess = SimpleNamespace(domain_id=3, node=SimpleNamespace(
        get_publishers_info_by_topic=lambda topic: [info(4464)]))
    monkeypatch.setattr(discovery, '_host_ports', lambda domain: {7410: 1, 7412: 2})
    monkeypatch.setattr(host_sockets, 'socket_holders',
                        lambda inodes: {1: frozenset({70000}), 2: frozenset({4464})})
    assert roles._unheard(sess, [70000])  # type: ignore[arg-type]
    assert roles._unheard(sess, [4464])  # type: ignore[arg-type]  # either may be the one
    monkeypatch.setattr(host_sockets, 'socket_holders', lambda inodes: {1: frozenset({70000})})
    assert not roles._unheard(sess, [70000])  # type: ignore[arg-type]  # no other: its own
