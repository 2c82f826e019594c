"""launch_yaml, as far as Python launch files use it (its launch description source)."""
