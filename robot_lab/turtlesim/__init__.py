"""turtlesim for the kit: the simulation (pure Python), its node and the tutorial nodes.

Jazzy's turtlesim is C++ with a Qt window and is not on PyPI. This package behaves as it
does for everything the tutorials touch; the window is a notebook widget
(`robot_lab.turtlesim_view()`), fed over ROS so a node started in a terminal can be watched.
"""

from robot_lab.turtlesim.turtle import CANVAS, Pen, RotateGoal, Turtle, TurtlePose
from robot_lab.turtlesim.world import FRAME_PERIOD, TurtleState, World

__all__ = ['CANVAS', 'FRAME_PERIOD', 'Pen', 'RotateGoal', 'Turtle', 'TurtlePose',
           'TurtleState', 'World']
