"""robot_lab's simulator: a physics engine from PyPI behind Gazebo Harmonic's names.

See `docs/architecture.md` (the `sim/` row) for what each module owns.
"""
