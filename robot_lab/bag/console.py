"""The lines `ros2 bag` prints: rclcpp's console format, `[LEVEL] [sec.nsec] [node]: text`."""

from __future__ import annotations

import time

__all__ = ['log_line']


def log_line(level: str, name: str, text: str) -> str:
    """One log line of node `name` as rclcpp's default console output writes it, now."""
    now = time.time_ns()
    return f'[{level}] [{now // 1_000_000_000}.{now % 1_000_000_000:09d}] [{name}]: {text}'
