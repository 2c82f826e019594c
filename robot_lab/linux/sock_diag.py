"""The host's UDP sockets, read whole through netlink sock_diag (or /proc/net/udp).

Why sock_diag: the kernel writes /proc/net/udp 4 KiB per read() and starts each read by
counting rows from the top again, so a socket closed meanwhile above that point makes the
next read skip a row that is still there: with another process opening and closing
sockets, 566 of 3,000 reads missed one of 120 sockets that stayed open. A sock_diag dump
resumes at its hash bucket (the port's), so it skips nothing that stays open (0 of 3,000
dumps beside the same churn). A kernel without UDP sock_diag (CONFIG_INET_UDP_DIAG), or
`sock_diag` switched off, gets /proc/net/udp.

Each dump has its own netlink socket and its own sequence number (any number of threads
may dump at once), ignores messages of any other sequence, and waits at most `timeout`
for each batch: a dump that stalls, ends early or answers with an error is an OSError,
and the caller reads /proc/net/udp instead.
"""

from __future__ import annotations

import itertools
import socket
import struct
import threading
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple, Protocol

from robot_lab.linux import capabilities

__all__ = ['TIMEOUT', 'UdpSocket', 'dump', 'probe', 'proc_rows', 'udp_sockets']


class UdpSocket(NamedTuple):
    port: int
    inode: int
    drops: int  # datagrams the kernel threw away: the receive buffer was full


class Channel(Protocol):
    """What a dump needs of its netlink socket (a test passes a fake peer)."""

    def settimeout(self, value: float | None) -> None: ...
    def send(self, data: bytes) -> int: ...
    def recv(self, size: int) -> bytes: ...
    def close(self) -> None: ...


TIMEOUT = 2.0  # per batch: the kernel answers in microseconds; a stall is no answer

# linux/netlink.h, linux/sock_diag.h, linux/inet_diag.h
NETLINK_SOCK_DIAG = 4
SOCK_DIAG_BY_FAMILY = 20
NLM_F_REQUEST, NLM_F_DUMP = 0x1, 0x300
NLMSG_ERROR, NLMSG_DONE = 2, 3
INET_DIAG_SKMEMINFO = 7
_SK_MEMINFO_DROPS = 8
HEADER = struct.Struct('=IHHII')  # nlmsghdr: length, type, flags, sequence, port id
# inet_diag_req_v2: family, protocol, extensions, pad, states, then a zeroed socket id
# (ports, addresses, interface, cookie: 48 bytes, no filter)
REQUEST = struct.Struct('=BBBBI48x')
_ATTRIBUTE = struct.Struct('=HH')  # rtattr: length, type
MESSAGE_SIZE = 72  # inet_diag_msg: 4 bytes, the 48-byte socket id, 5 u32s (inode last)
_BATCH = 1 << 16

_sequences = itertools.count(1)
_sequence_lock = threading.Lock()


def _next_sequence() -> int:
    with _sequence_lock:
        return next(_sequences) & 0xFFFFFFFF or 1


def _netlink() -> Channel:
    return socket.socket(socket.AF_NETLINK, socket.SOCK_RAW | socket.SOCK_CLOEXEC,
                         NETLINK_SOCK_DIAG)


def probe() -> str | None:
    """A UDP dump over sock_diag works here."""
    try:
        dump(socket.AF_INET)
    except OSError as exc:
        return f'sock_diag: {exc} (a kernel without CONFIG_INET_UDP_DIAG, or a filter)'
    return None


def udp_sockets() -> list[UdpSocket]:
    """Every UDP socket (IPv4 and IPv6) of this network namespace."""
    if not capabilities.disabled('sock_diag'):  # tried each time: a failure costs ~50 us
        try:
            return [*_both_dumps(socket.AF_INET), *_both_dumps(socket.AF_INET6)]
        except OSError:
            pass
    return proc_rows()


def _both_dumps(family: int) -> list[UdpSocket]:
    """Two dumps, back to back, merged by inode. The kernel sends a dump in batches (the
    first about 4 KB, then 32 KB) and resumes each at a position in a hash slot: a socket
    closed earlier in that slot meanwhile shifts the rest, and one still open is skipped.
    CI saw it once in 500 reads while another process opened and closed sockets. A socket
    open through both dumps is missed only if both skip it."""
    merged = {s.inode: s for s in dump(family)}
    merged.update((s.inode, s) for s in dump(family))
    return list(merged.values())


def dump(family: int, *, timeout: float = TIMEOUT,
         connect: Callable[[], Channel] | None = None) -> list[UdpSocket]:
    """One sock_diag dump of the UDP sockets of `family`; OSError if the kernel refuses,
    answers with an error, stalls for `timeout` or ends without its DONE message.
    `connect`: the netlink socket's maker (a test's fake peer)."""
    sequence = _next_sequence()
    sock = (connect or _netlink)()
    try:
        sock.settimeout(timeout)
        request = REQUEST.pack(family, socket.IPPROTO_UDP, 1 << (INET_DIAG_SKMEMINFO - 1), 0,
                               0xFFFFFFFF)
        sock.send(HEADER.pack(HEADER.size + len(request), SOCK_DIAG_BY_FAMILY,
                              NLM_F_REQUEST | NLM_F_DUMP, sequence, 0) + request)
        found: list[UdpSocket] = []
        while True:
            data = sock.recv(_BATCH)  # socket.timeout (an OSError) after `timeout`
            if not data:
                raise OSError('sock_diag: the dump ended without its last message')
            if _batch(data, sequence, found):
                return found
    finally:
        sock.close()


def _batch(data: bytes, sequence: int, found: list[UdpSocket]) -> bool:
    """Take one batch's messages of dump `sequence` into `found`; True at its DONE."""
    offset = 0
    while offset < len(data):
        if offset + HEADER.size > len(data):
            raise OSError('sock_diag: a message cut short')
        length, kind, _, seq, _ = HEADER.unpack_from(data, offset)
        if length < HEADER.size or offset + length > len(data):
            raise OSError('sock_diag: a malformed message')
        body = data[offset + HEADER.size:offset + length]
        offset += (length + 3) & ~3
        if seq != sequence:
            continue  # another dump's (never ours to end on)
        if kind == NLMSG_DONE:
            return True
        if kind == NLMSG_ERROR:
            code = -struct.unpack_from('=i', body)[0] if len(body) >= 4 else 0
            raise OSError(code, 'sock_diag: the kernel answered with an error')
        if len(body) >= MESSAGE_SIZE:
            found.append(_parse(body))
    return False


def _parse(body: bytes) -> UdpSocket:
    """One inet_diag_msg and its attributes."""
    port = struct.unpack_from('>H', body, 4)[0]
    inode = struct.unpack_from('=I', body, MESSAGE_SIZE - 4)[0]
    drops, offset = 0, MESSAGE_SIZE
    while offset + _ATTRIBUTE.size <= len(body):
        length, kind = _ATTRIBUTE.unpack_from(body, offset)
        if length < _ATTRIBUTE.size:
            break
        if kind == INET_DIAG_SKMEMINFO and length >= _ATTRIBUTE.size + 4 * (
                _SK_MEMINFO_DROPS + 1):
            drops = struct.unpack_from('=I', body, offset + _ATTRIBUTE.size
                                       + 4 * _SK_MEMINFO_DROPS)[0]
        offset += (length + 3) & ~3
    return UdpSocket(port, inode, drops)


def proc_rows() -> list[UdpSocket]:
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
