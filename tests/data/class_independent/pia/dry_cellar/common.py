"""A Node that declares its parameters from a table of defaults and keeps them as
attributes, so each node below only lists what it needs."""
from rclpy.node import Node


class ConfiguredNode(Node):
    DEFAULTS: dict = {}

    def __init__(self, name):
        super().__init__(name)
        for key, default in self.DEFAULTS.items():
            setattr(self, key, self.declare_parameter(key, default).value)
