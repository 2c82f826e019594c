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

__all__ = ['GUID_PID_BITS', 'UdpSocket', 'discovery_port', 'discovery_ports', 'socket_drops',
           'udp_sockets', 'unheard_ports']


# Fast DDS's well-known ports (RTPS 2.x 9.6.1.1): PB + DG * domain + d1 + PG * participant
# is a participant's metatraffic unicast (discovery) port (PB + DG * domain: domain_ports).
_PARTICIPANT_GAIN, _D1 = 2, 10
# Fast DDS writes only a pid's low 16 bits into its GUID prefix (bytes 4-5).
GUID_PID_BITS = 16


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
    mask = (1 << GUID_PID_BITS) - 1
    candidates = {port: {pid & mask for pid in holders[inode]}
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
