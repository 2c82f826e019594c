"""What the three reference nodes share: typed, ranged parameters and a clean main()."""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

__all__ = ['declare', 'run_node']

N = TypeVar('N')


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


def run_node(factory: Callable[[], Any], args: Sequence[str] | None = None) -> None:
    """rclpy.init, spin, and a clean exit (code 0, no traceback) on SIGINT or SIGTERM.

    SIGINT is re-armed first: a process started from a non-interactive shell inherits it
    ignored, and then Ctrl-C (or a launcher's SIGINT) would do nothing.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException

    signal.signal(signal.SIGINT, signal.default_int_handler)

    def _terminate(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, _terminate)
    rclpy.init(args=list(args) if args is not None else sys.argv)
    node = None
    try:
        node = factory()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.utilities.try_shutdown()
