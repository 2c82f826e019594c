"""ROS names in launch: namespaces pushed and nested as launch_ros does, rcl's rules."""

from __future__ import annotations

import re

__all__ = ['absolute_namespace', 'namespace_problem', 'node_name_problem', 'prefix_namespace']

_NODE_NAME = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')


_NS_TOKEN = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')


def prefix_namespace(base: str | None, namespace: str | None) -> str | None:
    """launch_ros's prefix_namespace: relative namespaces nest, absolute ones replace."""
    if base is None and namespace is None:
        return None
    if namespace is None:
        combined = base
    elif not base or namespace.startswith('/'):
        combined = namespace
    else:
        combined = ('' if base == '/' else base) + '/' + namespace
    assert combined is not None
    return combined if combined == '/' else combined.rstrip('/')


def absolute_namespace(namespace: str | None) -> str | None:
    if namespace is None:
        return None
    return namespace if namespace.startswith('/') else '/' + namespace


def namespace_problem(namespace: str) -> str | None:
    """rcl's namespace rules, as rclpy.validate_namespace applies them."""
    if namespace == '/':
        return None
    if not namespace.startswith('/'):
        return 'namespace must be absolute'
    if namespace.endswith('/'):
        return "namespace must not end with '/'"
    if '//' in namespace:
        return "namespace must not contain repeated '/'"
    for token in namespace[1:].split('/'):
        if not _NS_TOKEN.fullmatch(token):
            if token[:1].isdigit():
                return f"namespace token '{token}' must not start with a number"
            return f"namespace token '{token}' must contain only alphanumerics and '_'"
    return None


def node_name_problem(name: str) -> str | None:
    if not name:
        return 'node name must not be empty'
    if name[0].isdigit():
        return 'node name must not start with a number'
    if not _NODE_NAME.fullmatch(name):
        return "node name must not contain characters other than alphanumerics or '_'"
    return None
