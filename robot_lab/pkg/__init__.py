"""Packages: `index` (the ament index: packages, prefixes, executables), `create`,
`build` (colcon), `workspace`, `doctor`; the public names are re-exported by `robot_lab`.

This package re-exports nothing itself: the launcher needs only `index`, and every
millisecond before its first node starts counts.
"""
