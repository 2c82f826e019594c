"""robot_lab's stand-in for geometry_tutorials' turtle_tf2_py: the tf2 tutorials' turtle demo.

The executables, node names, parameters, topics and frames are the ones the tf2 pages of the
ROS 2 documentation name, so `ros2 launch turtle_tf2_py turtle_tf2_demo.launch.py` behaves as it
does on a Jazzy install. The code is the kit's own; a student's copies of the tutorial files live
in their own package (learning_tf2_py), not here.
"""
