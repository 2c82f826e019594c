"""What the three reference nodes share: typed, ranged parameters and a clean main()."""

from __future__ import annotations

import faulthandler
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

__all__ = ['STOP_LIMIT', 'declare', 'run_node']

N = TypeVar('N')
# Seconds from the first SIGINT or SIGTERM to a node's exit before it prints every
# thread's stack and exits with code 1. A launch sends SIGTERM 5 s after SIGINT and SIGKILL
# 10 s after that; a node stuck once told to stop (a callback that never returns, rclpy or
# DDS hanging in the shutdown) never acts on the flag the signals set, so it would die at
# SIGKILL without saying where it hung. Once in 5 loaded CI runs a sensor stopped 0.34 s
# after it started hung so (where, unknown: a node stuck in C before its handler ran is not
# covered, and prints nothing).
STOP_LIMIT = 10.0


def declare(
    node: Any,
    name: str,
    default: int | float | str | bool,
    description: str,
    value_range: tuple[float, float] | None = None,
) -> Any:
    """Declare `name` with a ParameterDescriptor, so tools show its type and range.

    rclpy itself then refuses out-of-range values with a reason, and the node keeps running.
    """
    from rcl_interfaces.msg import (
        FloatingPointRange,
        IntegerRange,
        ParameterDescriptor,
    )

    descriptor = ParameterDescriptor(description=description)
    if value_range is not None:
        low, high = value_range
        if isinstance(default, bool) or not isinstance(default, int | float):
            raise TypeError(f'parameter {name}: a range needs a numeric default')
        if isinstance(default, int):
            descriptor.integer_range = [
                IntegerRange(from_value=int(low), to_value=int(high), step=1)
            ]
        else:
            descriptor.floating_point_range = [
                FloatingPointRange(from_value=float(low), to_value=float(high), step=0.0)
            ]
    return node.declare_parameter(name, default, descriptor)


def run_node(factory: Callable[[], Any], args: Sequence[str] | None = None,
             threads: int = 1) -> None:
    """rclpy.init, spin, and a clean exit (code 0, no traceback) on SIGINT or SIGTERM.

    rclpy's own signal handlers shut the context down from inside the handler, which races
    with a message being taken (`RuntimeError` at Ctrl-C). Instead the signal only sets a
    flag; the spin loop returns to Python at least every 0.1 s to see it, then the node and
    the context are shut down in order. Re-arming SIGINT also undoes the "ignored"
    disposition a process inherits when started with `&` from a non-interactive shell.
    The first signal also arms faulthandler's watchdog (a C thread, which needs no GIL):
    a node not gone `STOP_LIMIT` s later prints where each thread is and exits.
    `threads` > 1 spins a MultiThreadedExecutor, for a node whose callback may block while
    others must run (an action server's execute callback and its cancel requests).
    """
    import rclpy
    from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    stop = threading.Event()

    def _request_stop(signum: int, frame: object) -> None:
        if not stop.is_set():
            faulthandler.dump_traceback_later(STOP_LIMIT, exit=True)
        stop.set()

    signal.signal(signal.SIGINT, _request_stop)
    signal.signal(signal.SIGTERM, _request_stop)
    rclpy.init(
        args=list(args) if args is not None else sys.argv,
        signal_handler_options=SignalHandlerOptions.NO,
    )
    node = None
    try:
        node = factory()
        executor = (SingleThreadedExecutor() if threads <= 1
                    else MultiThreadedExecutor(num_threads=threads))
        executor.add_node(node)
        while not stop.is_set() and rclpy.utilities.ok():
            executor.spin_once(timeout_sec=0.1)
        executor.shutdown()
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.utilities.try_shutdown()
