"""tf2, written for the kit from geometry2's documented behaviour (PyPI has no tf2).

Students import upstream's module paths (`tf2_ros`, `tf2_py`, `tf2_geometry_msgs`), which the
kit installs into its venv as thin packages over these modules; see docs/architecture.md.
"""
