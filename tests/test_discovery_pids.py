"""Discovery's process rule without DDS: a GUID prefix carries only a pid's low 16 bits,
so on a host whose pid_max exceeds 65536 (4194304 under systemd on 64-bit hosts) two
processes can share them, and a heard participant of one must not vouch for the other."""

from __future__ import annotations

import os
import socket

from robot_lab.graph.host_sockets import guid_pid_bits, unheard_ports, unheard_processes
from robot_lab.linux.procfs import socket_holders

# 70000 and 4464 share their low 16 bits (70000 - 65536 = 4464).
LOW, HIGH = 4464, 70000


def test_a_pid_that_shares_its_low_bits_with_a_heard_one_is_not_heard() -> None:
    ports = {7410: 1, 7412: 2}
    holders = {1: frozenset({HIGH}), 2: frozenset({LOW})}
    assert len(unheard_ports(ports, [LOW], holders)) == 1  # one participant, two processes
    assert unheard_ports(ports, [LOW, LOW], holders) == []  # both heard


def test_each_participant_of_one_process_accounts_for_one_port() -> None:
    ports = {7410: 1, 7412: 2}
    holders = {1: frozenset({500}), 2: frozenset({500})}
    assert unheard_ports(ports, [500, 500], holders) == []
    assert len(unheard_ports(ports, [500], holders)) == 1


def test_an_inherited_socket_is_heard_through_either_holder() -> None:
    assert unheard_ports({7410: 1}, [501], {1: frozenset({500, 501})}) == []


def test_ports_are_matched_so_that_as_many_as_possible_are_heard() -> None:
    """A port two processes hold, another held by one of them: the shared one is matched
    to the other process's participant, not taken from the one the second port needs."""
    ports = {7410: 1, 7412: 2}
    holders = {1: frozenset({600, 601}), 2: frozenset({600})}
    assert unheard_ports(ports, [600, 601], holders) == []
    assert unheard_ports(ports, [601], holders) == [7412]


def test_ports_whose_holders_cannot_be_read_count_as_heard() -> None:
    assert unheard_ports({7410: 1}, [], {}) == []


def test_a_process_is_not_heard_through_another_with_its_pid_bits() -> None:
    """The grader's wait for its launched processes (roles._unheard): one heard participant
    for two processes that share its bits vouches for neither (either may be unheard)."""
    assert guid_pid_bits(HIGH) == guid_pid_bits(LOW) == LOW
    ports = {7410: 1, 7412: 2}
    holders = {1: frozenset({HIGH}), 2: frozenset({LOW})}
    assert unheard_processes([HIGH, LOW], [LOW], ports, holders) == [HIGH, LOW]
    assert unheard_processes([HIGH, LOW], [LOW, LOW], ports, holders) == []
    assert unheard_processes([HIGH, 500], [LOW], {7410: 1}, holders) == [500]  # no port yet
    assert unheard_processes([HIGH], [LOW], {7410: 1}, holders) == []  # its bits alone


def test_without_ports_each_participant_vouches_for_one_process() -> None:
    assert unheard_processes([LOW, HIGH], [LOW], None) == [HIGH]
    assert unheard_processes([LOW, HIGH], [LOW, LOW], None) == []
    assert unheard_processes([LOW, 500], [500, LOW], None) == []


def test_holders_are_whole_pids() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        inode = os.fstat(sock.fileno()).st_ino
        assert socket_holders([inode]) == {inode: frozenset({os.getpid()})}
