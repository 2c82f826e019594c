"""The three reference nodes of the seed lab: sensor → controller → robot.

Importing this package does not import rclpy; import the node modules for the classes.
"""

NODE_EXECUTABLES = ('sensor_node', 'controller_node', 'robot_node')

__all__ = ['NODE_EXECUTABLES']
