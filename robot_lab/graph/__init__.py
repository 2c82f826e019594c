"""The running ROS graph as data: nodes, topics, parameters, services, and its picture.

`robot_lab.graph.api` holds the functions (re-exported by `robot_lab`); `view` draws the
graph; `daemon` and `expected` make one-shot CLI queries fast. Importing this package
loads nothing else (the launcher imports `expected` and must start its nodes at once); the
API names resolve on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = [
    'Endpoint', 'HzStats', 'NodeInfo', 'ParamDescription', 'SetResult', 'TopicInfo', 'echo',
    'interface_show', 'node_info', 'node_list', 'param_describe', 'param_dump', 'param_get',
    'param_list', 'param_load', 'param_set', 'publish', 'service_list', 'topic_hz',
    'topic_info', 'topic_list', 'topic_type', 'wait_for_nodes', 'wait_for_topic',
]


def __getattr__(name: str) -> Any:
    if name in __all__:
        return getattr(importlib.import_module('robot_lab.graph.api'), name)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
