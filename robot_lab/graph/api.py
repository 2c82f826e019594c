"""The graph inspection API in one place: data for notebooks, widgets, tests and the CLI.

Each function returns data (the `robot-lab` verbs only print it). Every wait has a
timeout and ends in a GraphError that says what is missing and how to check. All take an
optional `session=` (default: `robot_lab.context.session()`).
"""

from __future__ import annotations

from robot_lab.graph.interfaces import interface_show
from robot_lab.graph.nodes import NodeInfo, node_info, node_list, wait_for_nodes
from robot_lab.graph.parameters import (
    ParamDescription,
    SetResult,
    param_describe,
    param_dump,
    param_get,
    param_list,
    param_load,
    param_set,
)
from robot_lab.graph.services import service_list
from robot_lab.graph.topics import (
    Endpoint,
    HzStats,
    TopicInfo,
    echo,
    publish,
    topic_hz,
    topic_info,
    topic_list,
    topic_type,
    wait_for_topic,
)

__all__ = [
    'Endpoint',
    'HzStats',
    'NodeInfo',
    'ParamDescription',
    'SetResult',
    'TopicInfo',
    'echo',
    'interface_show',
    'node_info',
    'node_list',
    'param_describe',
    'param_dump',
    'param_get',
    'param_list',
    'param_load',
    'param_set',
    'publish',
    'service_list',
    'topic_hz',
    'topic_info',
    'topic_list',
    'topic_type',
    'wait_for_nodes',
    'wait_for_topic',
]
