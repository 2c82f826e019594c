"""The host's UDP sockets as discovery reads them: the DDS discovery ports bound, their
processes, and the datagrams the kernel dropped on this process's sockets (see
graph/discovery.py). The table itself comes from robot_lab.linux.sock_diag (netlink
sock_diag, else /proc/net/udp), the processes from robot_lab.linux.procfs.
"""

from __future__ import annotations

from robot_lab.domain import domain_ports
from robot_lab.linux.procfs import own_socket_inodes, socket_holders
from robot_lab.linux.sock_diag import UdpSocket, udp_sockets

__all__ = ['UdpSocket', 'discovery_port', 'discovery_ports', 'own_sockets', 'port_holders',
           'socket_drops', 'udp_sockets']


# Fast DDS's well-known ports (RTPS 2.x 9.6.1.1): PB + DG * domain + d1 + PG * participant
# is a participant's metatraffic unicast (discovery) port (PB + DG * domain: domain_ports).
_PARTICIPANT_GAIN, _D1 = 2, 10


def own_sockets() -> set[int]:
    """The inodes of the sockets this process holds."""
    return own_socket_inodes()


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


def port_holders(inodes: frozenset[int]) -> list[set[int]]:
    """For each of these sockets that this user may trace, the pids (low 16 bits, as Fast
    DDS writes them into a GUID) of the processes in this PID namespace that hold it;
    sockets held elsewhere are left out (see procfs.socket_holders)."""
    return socket_holders(inodes, pid_bits=16)
