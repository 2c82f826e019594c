"""What every node here has in common: a name, settings read once, and a logger line
saying which settings were used."""
from abc import ABC, abstractmethod

from rclpy.node import Node


class LabNode(Node, ABC):
    SETTINGS = ()

    def __init__(self, name):
        super().__init__(name)
        self.cfg = {key: self.declare_parameter(key, value).value
                    for key, value in self.SETTINGS}
        if self.cfg:
            self.get_logger().info(', '.join(f'{k}={v}' for k, v in self.cfg.items()))
        self.setup()

    @abstractmethod
    def setup(self):
        """Create the node's publishers, subscriptions and timers."""
