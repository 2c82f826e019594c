"""The running ROS graph as data: nodes, topics, parameters, services, and its picture.

`api` holds the functions (re-exported by `robot_lab`); `view` draws the graph; `daemon`
and `expected` make one-shot CLI queries fast. This package re-exports nothing itself: the
launcher imports `expected` and must start its nodes without loading the rest.
"""
