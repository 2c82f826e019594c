"""The `launch` / `launch_ros` Python API for Python launch files, backed by robot_lab.

This directory goes on sys.path only while a Python launch file is loaded, and only if
the real `launch` package is not importable: a real ROS install is never shadowed.
The classes are robot_lab's own launch actions with launch's constructor signatures.
"""
