"""The graph inspection API in one place: data for notebooks, widgets, tests and the CLI.

Each function returns data (the `robot-lab` verbs only print it). Every wait has a
timeout and ends in a GraphError that says what is missing and how to check. All take an
optional `session=` (default: `robot_lab.rclpy_session.session()`).
"""

from __future__ import annotations

from robot_lab.graph.actions import (
    ActionGoal,
    ActionInfo,
    action_info,
    action_list,
    action_type,
    send_goal,
)
from robot_lab.graph.interfaces import (
    interface_list,
    interface_package,
    interface_packages,
    interface_proto,
    interface_show,
)
from robot_lab.graph.nodes import NodeInfo, node_info, node_list, wait_for_nodes
from robot_lab.graph.parameters import (
    ParamDescription,
    SetResult,
    param_delete,
    param_describe,
    param_dump,
    param_get,
    param_list,
    param_load,
    param_set,
)
from robot_lab.graph.services import (
    ServiceInfo,
    call_service,
    service_find,
    service_info,
    service_list,
    service_type,
)
from robot_lab.graph.topic_stats import BwStats, DelayStats, topic_bw, topic_delay
from robot_lab.graph.topics import (
    Endpoint,
    HzStats,
    TopicInfo,
    echo,
    publish,
    topic_find,
    topic_hz,
    topic_info,
    topic_list,
    topic_type,
    wait_for_topic,
)

__all__ = [
    'ActionGoal',
    'ActionInfo',
    'BwStats',
    'DelayStats',
    'Endpoint',
    'HzStats',
    'NodeInfo',
    'ParamDescription',
    'ServiceInfo',
    'SetResult',
    'TopicInfo',
    'action_info',
    'action_list',
    'action_type',
    'call_service',
    'echo',
    'interface_list',
    'interface_package',
    'interface_packages',
    'interface_proto',
    'interface_show',
    'node_info',
    'node_list',
    'param_delete',
    'param_describe',
    'param_dump',
    'param_get',
    'param_list',
    'param_load',
    'param_set',
    'publish',
    'send_goal',
    'service_find',
    'service_info',
    'service_list',
    'service_type',
    'topic_bw',
    'topic_delay',
    'topic_find',
    'topic_hz',
    'topic_info',
    'topic_list',
    'topic_type',
    'wait_for_nodes',
    'wait_for_topic',
]
