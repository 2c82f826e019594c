"""Everything the kit asks of Linux itself, in one place: libc, prctl, clone/fork, pidfds,
namespaces and mounts, netlink sock_diag, the /proc scans.

The rest of the kit calls these modules and never ctypes or /proc: a machine unlike the
one the kit was built on (a container's seccomp profile, an old kernel, a distribution
that restricts user namespaces) then has one place where each capability is probed, and
one switch (`capabilities`, `ROBOT_LAB_DISABLE=NAME,...`) that makes the kit take the
path it takes without it. `robot-lab doctor` prints the table.

Modules: `libc` (loading, errno), `prctl` (parent-death signal, name, no_new_privs, the
process image), `capabilities` (probes and switches), `pidfd`, `signals` (signalfd),
`fork` (the fork server's fork), `namespaces` (unshare, mount), `sock_diag` (the host's
UDP sockets), `procfs`.
Every module here is thread-safe; none imports the rest of the kit.
"""
