"""What every simulator command says it is, without importing the engine (a quick start)."""

from __future__ import annotations

from importlib import metadata

__all__ = ['identity']


def identity() -> str:
    """`--version` and the first log line: robot_lab's simulator and its engine, not Gazebo."""
    from robot_lab import __version__

    try:
        engine = metadata.version('mujoco-core')
    except metadata.PackageNotFoundError:  # a MuJoCo installed another way
        import mujoco  # type: ignore[import-untyped]  # no stubs nor py.typed

        engine = str(mujoco.__version__)
    return (f"robot_lab's simulator {__version__} on MuJoCo {engine} "
            f"(Gazebo Harmonic's commands, topics and systems; not Gazebo)")
