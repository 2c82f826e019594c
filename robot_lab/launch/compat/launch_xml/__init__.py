"""launch_xml, as far as Python launch files use it (its launch description source)."""
