"""The host's UDP sockets as discovery reads them: the DDS discovery ports bound, their
processes, and the datagrams the kernel dropped on this process's sockets (see
graph/discovery.py). The table itself comes from robot_lab.linux.sock_diag (netlink
sock_diag, else /proc/net/udp), the processes from robot_lab.linux.procfs.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping

from robot_lab.domain import domain_ports
from robot_lab.linux.procfs import own_socket_inodes, socket_holders
from robot_lab.linux.sock_diag import UdpSocket, udp_sockets

__all__ = ['GUID_PID_BITS', 'UdpSocket', 'discovery_port', 'discovery_ports', 'guid_pid_bits',
           'socket_drops', 'udp_sockets', 'unheard_ports', 'unheard_processes']


# Fast DDS's well-known ports (RTPS 2.x 9.6.1.1): PB + DG * domain + d1 + PG * participant
# is a participant's metatraffic unicast (discovery) port (PB + DG * domain: domain_ports).
_PARTICIPANT_GAIN, _D1 = 2, 10
# Fast DDS writes only a pid's low 16 bits into its GUID prefix (bytes 4-5).
GUID_PID_BITS = 16


def guid_pid_bits(pid: int) -> int:
    """The part of a whole pid that a Fast DDS GUID prefix carries (two pids can share it)."""
    return pid & ((1 << GUID_PID_BITS) - 1)


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
    mine = own_socket_inodes()
    return sum(s.drops for s in udp_sockets() if s.inode in mine)


def unheard_ports(ports: Mapping[int, int], heard: Iterable[int],
                  holders: Mapping[int, frozenset[int]] | None = None) -> list[int]:
    """The discovery ports (`ports`: port -> socket inode) that no heard participant
    accounts for; ports whose holders cannot be read are taken as heard.

    `heard` has one entry per participant heard: the pid bits its GUID prefix carries.
    Those are a pid's low 16 bits, so where pid_max exceeds 65536 (4194304 under systemd
    on 64-bit hosts) two processes can share them: a heard participant of one would vouch
    for an unheard one of the other. So each heard participant accounts for one port
    only, of a process whose pid it matches, and the ports are matched to participants so
    that as many as possible are accounted for (augmenting paths; a few dozen ports)."""
    holders = socket_holders(ports.values()) if holders is None else holders
    candidates = {port: {guid_pid_bits(pid) for pid in holders[inode]}
                  for port, inode in ports.items() if holders.get(inode)}
    slots = [(bits, k) for bits, count in Counter(heard).items() for k in range(count)]
    owner: dict[tuple[int, int], int] = {}

    def assign(port: int, tried: set[tuple[int, int]]) -> bool:
        for slot in slots:
            if slot[0] in candidates[port] and slot not in tried:
                tried.add(slot)
                if slot not in owner or assign(owner[slot], tried):
                    owner[slot] = port
                    return True
        return False

    return sorted(port for port in candidates if not assign(port, set()))


def unheard_processes(pids: Iterable[int], heard: Iterable[int],
                      ports: Mapping[int, int] | None,
                      holders: Mapping[int, frozenset[int]] | None = None) -> list[int]:
    """The processes among `pids` not known to be heard (`heard`: the pid bits of each
    participant heard, as in unheard_ports).

    A participant names its process by pid bits only. With the host's discovery ports
    (`ports`, None when unknown) and their holders' whole pids, a process counts as heard
    when its bits are heard at least as often as processes holding a port have them: of
    two processes sharing the bits with one participant heard, either may be the one not
    heard, so neither is taken as heard; a process holding no port has no participant
    yet. Without the ports, each heard participant vouches for one process of its bits."""
    heard_bits = Counter(heard)
    if ports is None:
        missing = []
        for pid in pids:
            if heard_bits[guid_pid_bits(pid)] > 0:
                heard_bits[guid_pid_bits(pid)] -= 1
            else:
                missing.append(pid)
        return missing
    holders = socket_holders(ports.values()) if holders is None else holders
    sharing: dict[int, set[int]] = {}
    for inode in ports.values():
        for pid in holders.get(inode, ()):
            sharing.setdefault(guid_pid_bits(pid), set()).add(pid)
    return [pid for pid in pids
            if pid not in (same := sharing.get(guid_pid_bits(pid), set()))
            or heard_bits[guid_pid_bits(pid)] < len(same)]
