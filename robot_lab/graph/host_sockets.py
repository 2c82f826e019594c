"""The host's UDP sockets, read whole: the DDS discovery ports bound, their processes, and
the datagrams the kernel dropped on this process's sockets (see graph/discovery.py).

The table is read through the kernel's sock_diag netlink interface, not /proc/net/udp.
The kernel writes /proc/net/udp 4 KiB per read() and starts each read by counting rows
from the top again, so a socket closed meanwhile above that point makes the next read
skip a row that is still there: with another process opening and closing sockets, 566
of 3,000 reads missed one of 120 sockets that stayed open. A cold `node list` that
missed its own port this way could not count the host's participants at all, and one
that missed a participant not yet heard called the graph complete without it.
A sock_diag dump resumes at its hash bucket (the port's), so it skips nothing that
stays open (0 of 3,000 dumps beside the same churn). A kernel without UDP sock_diag
(CONFIG_INET_UDP_DIAG) gets /proc/net/udp.
"""

from __future__ import annotations

import contextlib
import os
import socket
import struct
from pathlib import Path
from typing import NamedTuple

from robot_lab.domain import domain_ports

__all__ = ['UdpSocket', 'discovery_port', 'discovery_ports', 'own_sockets', 'port_holders',
           'socket_drops', 'udp_sockets']


class UdpSocket(NamedTuple):
    port: int
    inode: int
    drops: int  # datagrams the kernel threw away: the receive buffer was full


# Fast DDS's well-known ports (RTPS 2.x 9.6.1.1): PB + DG * domain + d1 + PG * participant
# is a participant's metatraffic unicast (discovery) port (PB + DG * domain: domain_ports).
_PARTICIPANT_GAIN, _D1 = 2, 10

# linux/netlink.h, linux/sock_diag.h, linux/inet_diag.h
_NETLINK_SOCK_DIAG = 4
_SOCK_DIAG_BY_FAMILY = 20
_NLM_F_REQUEST, _NLM_F_DUMP = 0x1, 0x300
_NLMSG_ERROR, _NLMSG_DONE = 2, 3
_INET_DIAG_SKMEMINFO = 7
_SK_MEMINFO_DROPS = 8
_HEADER = struct.Struct('=IHHII')  # nlmsghdr: length, type, flags, sequence, port id
# inet_diag_req_v2: family, protocol, extensions, pad, states, then a zeroed socket id
# (ports, addresses, interface, cookie: 48 bytes, no filter)
_REQUEST = struct.Struct('=BBBBI48x')
_ATTRIBUTE = struct.Struct('=HH')  # rtattr: length, type
_MESSAGE_SIZE = 72  # inet_diag_msg: 4 bytes, the 48-byte socket id, 5 u32s (inode last)
_sequence = 0


def udp_sockets() -> list[UdpSocket]:
    """Every UDP socket (IPv4 and IPv6) of this network namespace."""
    try:
        return [*_both_dumps(socket.AF_INET), *_both_dumps(socket.AF_INET6)]
    except OSError:
        return list(_proc_rows())


def _both_dumps(family: int) -> list[UdpSocket]:
    """Two dumps, back to back, merged by inode. The kernel sends a dump in batches (the
    first about 4 KB, then 32 KB) and resumes each at a position in a hash slot: a socket
    closed earlier in that slot meanwhile shifts the rest, and one still open is skipped.
    CI saw it once in 500 reads while another process opened and closed sockets. A socket
    open through both dumps is missed only if both skip it."""
    merged = {s.inode: s for s in _dump(family)}
    merged.update((s.inode, s) for s in _dump(family))
    return list(merged.values())


def _dump(family: int) -> list[UdpSocket]:
    global _sequence
    _sequence += 1
    with socket.socket(socket.AF_NETLINK, socket.SOCK_RAW | socket.SOCK_CLOEXEC,
                       _NETLINK_SOCK_DIAG) as sock:
        request = _REQUEST.pack(family, socket.IPPROTO_UDP, 1 << (_INET_DIAG_SKMEMINFO - 1),
                                0, 0xFFFFFFFF)
        sock.send(_HEADER.pack(_HEADER.size + len(request), _SOCK_DIAG_BY_FAMILY,
                               _NLM_F_REQUEST | _NLM_F_DUMP, _sequence, 0) + request)
        found: list[UdpSocket] = []
        while True:
            data = sock.recv(1 << 16)
            if not data:
                raise OSError('sock_diag: the dump ended without its last message')
            offset = 0
            while offset + _HEADER.size <= len(data):
                length, kind, _, sequence, _ = _HEADER.unpack_from(data, offset)
                if length < _HEADER.size:
                    raise OSError('sock_diag: a malformed message')
                body = data[offset + _HEADER.size:offset + length]
                offset += (length + 3) & ~3
                if sequence != _sequence:
                    continue
                if kind == _NLMSG_DONE:
                    return found
                if kind == _NLMSG_ERROR:
                    raise OSError(-struct.unpack_from('=i', body)[0], 'sock_diag')
                if len(body) >= _MESSAGE_SIZE:
                    found.append(_parse(body))


def _parse(body: bytes) -> UdpSocket:
    """One inet_diag_msg and its attributes."""
    port = struct.unpack_from('>H', body, 4)[0]
    inode = struct.unpack_from('=I', body, _MESSAGE_SIZE - 4)[0]
    drops, offset = 0, _MESSAGE_SIZE
    while offset + _ATTRIBUTE.size <= len(body):
        length, kind = _ATTRIBUTE.unpack_from(body, offset)
        if length < _ATTRIBUTE.size:
            break
        if kind == _INET_DIAG_SKMEMINFO and length >= _ATTRIBUTE.size + 4 * (
                _SK_MEMINFO_DROPS + 1):
            drops = struct.unpack_from('=I', body, offset + _ATTRIBUTE.size
                                       + 4 * _SK_MEMINFO_DROPS)[0]
        offset += (length + 3) & ~3
    return UdpSocket(port, inode, drops)


def _proc_rows() -> list[UdpSocket]:
    """The same from /proc/net/udp and udp6 (port: field 1, inode: 9, drops: 12), which
    can miss a row while sockets come and go (above)."""
    rows = []
    for table in (Path('/proc/net/udp'), Path('/proc/net/udp6')):
        try:
            lines = table.read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            if len(fields) >= 13:
                rows.append(UdpSocket(int(fields[1].rsplit(':', 1)[1], 16), int(fields[9]),
                                      int(fields[12])))
    return rows


def own_sockets() -> set[int]:
    """The inodes of the sockets this process holds."""
    inodes = set()
    with contextlib.suppress(OSError):
        for fd in os.listdir('/proc/self/fd'):
            with contextlib.suppress(OSError):  # closed meanwhile
                link = os.readlink(f'/proc/self/fd/{fd}')
                if link.startswith('socket:['):
                    inodes.add(int(link[8:-1]))
    return inodes


def discovery_port(domain_id: int, participant_id: int) -> int:
    """The discovery (metatraffic unicast) port of participant `participant_id`."""
    return domain_ports(domain_id).start + _D1 + _PARTICIPANT_GAIN * participant_id


def discovery_ports(domain_id: int, sockets: list[UdpSocket] | None = None) -> dict[int, int]:
    """Bound discovery ports of this domain on this host -> their socket inodes."""
    first, ports = discovery_port(domain_id, 0), domain_ports(domain_id)
    return {s.port: s.inode for s in (udp_sockets() if sockets is None else sockets)
            if s.port in ports and s.port >= first and (s.port - first) % _PARTICIPANT_GAIN == 0}


def socket_drops() -> int:
    """Datagrams the kernel dropped (receive buffer full) on this process's UDP sockets."""
    mine = own_sockets()
    return sum(s.drops for s in udp_sockets() if s.inode in mine)


_holders: dict[frozenset[int], list[set[int]]] = {}


def port_holders(inodes: frozenset[int]) -> list[set[int]]:
    """For each of these sockets that this user may trace, the pids (low 16 bits) of the
    processes in this PID namespace that hold it (a child that inherited the socket holds
    it too); sockets held elsewhere are left out. Cached per set of sockets: a scan of
    /proc takes ~2 ms per 150 processes."""
    if inodes in _holders:
        return _holders[inodes]
    wanted = {f'socket:[{inode}]': inode for inode in inodes}
    try:
        own_ns = os.readlink('/proc/self/ns/pid')
    except OSError:
        return []
    by_inode: dict[int, set[int]] = {}
    foreign: set[int] = set()
    for entry in os.scandir('/proc'):
        if not entry.name.isdigit():
            continue
        try:
            fds = os.listdir(f'/proc/{entry.name}/fd')
        except OSError:
            continue  # gone, or another user's
        held = set()
        for fd in fds:
            with contextlib.suppress(OSError):
                link = os.readlink(f'/proc/{entry.name}/fd/{fd}')
                if link in wanted:
                    held.add(wanted[link])
        if not held:
            continue
        try:  # a process in another PID namespace writes its own view of its pid
            same = os.readlink(f'/proc/{entry.name}/ns/pid') == own_ns
        except OSError:
            same = False
        for inode in held:
            if same:
                by_inode.setdefault(inode, set()).add(int(entry.name) & 0xFFFF)
            else:
                foreign.add(inode)
    found = [pids for inode, pids in by_inode.items() if inode not in foreign]
    if len(_holders) > 64:
        _holders.clear()
    _holders[inodes] = found
    return found
