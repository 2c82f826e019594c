"""Every launch action, one module each; importing this package registers their tags.

Adding a tag: write its module (an action class with `@register('tag')` and a
`parse(entity)` classmethod, see registry.py) and add its name to the list below.
"""

from __future__ import annotations

from robot_lab.launch.actions import (  # noqa: F401  (imported to register their tags)
    arguments,
    environment,
    event_handlers,
    execute_process,
    group,
    include,
    lifecycle_node,
    log,
    namespace,
    node,
    opaque,
    ros_globals,
    shutdown,
    timer,
    unavailable,
)
