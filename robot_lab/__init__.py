"""robot_lab: a Jupyter-first ROS 2 Jazzy course kit, with ROS 2 from PyPI wheels.

Importing robot_lab is cheap (no rclpy): each public name below is loaded from its home
module on first use. The table `_API` is the whole public API and says where each lives.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = '0.1.0'

# name -> home module (one obvious home for each thing, named after its ROS concept)
_API: dict[str, str] = {
    # errors
    'RobotLabError': 'robot_lab.errors',
    'LaunchError': 'robot_lab.errors',
    'ParamFileError': 'robot_lab.errors',
    'PackageError': 'robot_lab.errors',
    'PackageNotFoundError': 'robot_lab.errors',
    'ExecutableNotFoundError': 'robot_lab.errors',
    'GraphError': 'robot_lab.errors',
    'BagError': 'robot_lab.errors',
    # environment and session
    'apply_ros_defaults': 'robot_lab.env',
    'session': 'robot_lab.rclpy_session',
    'Session': 'robot_lab.rclpy_session',
    # packages
    'package_share': 'robot_lab.pkg.index',
    'package_prefix': 'robot_lab.pkg.index',
    'find_executable': 'robot_lab.pkg.index',
    'create_package': 'robot_lab.pkg.create',
    'build': 'robot_lab.pkg.build',
    'use_workspace': 'robot_lab.pkg.workspace',
    'workspace_dir': 'robot_lab.pkg.workspace',
    'doctor': 'robot_lab.pkg.doctor',
    # parameter files
    'load_param_file': 'robot_lab.params',
    # launch
    'launch': 'robot_lab.launch.api',
    'LaunchHandle': 'robot_lab.launch.api',
    'describe_launch': 'robot_lab.launch.api',
    # graph inspection (data; the CLI prints it, widgets draw it)
    'node_list': 'robot_lab.graph.api',
    'node_info': 'robot_lab.graph.api',
    'topic_list': 'robot_lab.graph.api',
    'topic_info': 'robot_lab.graph.api',
    'topic_type': 'robot_lab.graph.api',
    'echo': 'robot_lab.graph.api',
    'topic_hz': 'robot_lab.graph.api',
    'publish': 'robot_lab.graph.api',
    'param_list': 'robot_lab.graph.api',
    'param_get': 'robot_lab.graph.api',
    'param_set': 'robot_lab.graph.api',
    'param_delete': 'robot_lab.graph.api',
    'param_describe': 'robot_lab.graph.api',
    'param_dump': 'robot_lab.graph.api',
    'param_load': 'robot_lab.graph.api',
    'service_list': 'robot_lab.graph.api',
    'service_type': 'robot_lab.graph.api',
    'service_find': 'robot_lab.graph.api',
    'service_info': 'robot_lab.graph.api',
    'call_service': 'robot_lab.graph.api',
    'action_list': 'robot_lab.graph.api',
    'action_type': 'robot_lab.graph.api',
    'action_info': 'robot_lab.graph.api',
    'send_goal': 'robot_lab.graph.api',
    'topic_find': 'robot_lab.graph.api',
    'topic_bw': 'robot_lab.graph.api',
    'topic_delay': 'robot_lab.graph.api',
    'interface_show': 'robot_lab.graph.api',
    'interface_list': 'robot_lab.graph.api',
    'interface_package': 'robot_lab.graph.api',
    'interface_packages': 'robot_lab.graph.api',
    'interface_proto': 'robot_lab.graph.api',
    'wait_for_nodes': 'robot_lab.graph.api',
    'wait_for_topic': 'robot_lab.graph.api',
    'graph_view': 'robot_lab.graph.view',
    # bags
    'record': 'robot_lab.bag.record',
    'play': 'robot_lab.bag.play',
    'bag_info': 'robot_lab.bag.info',
    'read_topic': 'robot_lab.bag.read',
    # notebook widgets
    'plot': 'robot_lab.widgets.plot',
    'sliders': 'robot_lab.widgets.sliders',
    'console': 'robot_lab.widgets.console',
    'launch_panel': 'robot_lab.widgets.launch_panel',
    'recorder': 'robot_lab.widgets.bag',
    'player': 'robot_lab.widgets.bag',
    'robot_view': 'robot_lab.widgets.robot_view',
    'close_widgets': 'robot_lab.widgets.output',
    'RobotView': 'robot_lab.widgets.robot_view',
    'turtlesim_view': 'robot_lab.widgets.turtlesim_view',
    'TurtlesimView': 'robot_lab.widgets.turtlesim_view',
    'joint_sliders': 'robot_lab.widgets.joint_sliders',
    'JointSliders': 'robot_lab.widgets.joint_sliders',
    'teleop': 'robot_lab.widgets.teleop',
    'Teleop': 'robot_lab.widgets.teleop',
    # tf2 (the tf2_ros API itself is the kit package tf2_ros: `import tf2_ros`)
    'view_frames': 'robot_lab.tf2.view_frames',
    'frames_figure': 'robot_lab.tf2.view_frames',
    'tf_buffer': 'robot_lab.tf2.listener',
    # the 3D view (RViz's job)
    'scene_view': 'robot_lab.scene.view',
    'SceneView': 'robot_lab.scene.view',
    # the simulator (Gazebo's job): worlds, robots, world control, its shapes for scene_view
    'Simulation': 'robot_lab.sim.simulation',
    'world_control': 'robot_lab.sim.control',
    'gz_topics': 'robot_lab.sim.control',
    'bridge_hint': 'robot_lab.sim.control',
    'world_markers': 'robot_lab.sim.markers',
    'sim_view': 'robot_lab.sim.sim_view',
    'Trial': 'robot_lab.sim.trial',  # a controller against a world, judged by ground truth
    'TrialResult': 'robot_lab.sim.trial_result',
}

__all__ = sorted(_API)


def __getattr__(name: str) -> Any:
    module = _API.get(name)
    if module is None:
        raise AttributeError(f'module robot_lab has no attribute {name!r}')
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))


if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from robot_lab.env import apply_ros_defaults
    from robot_lab.errors import (
        BagError,
        ExecutableNotFoundError,
        GraphError,
        LaunchError,
        PackageError,
        PackageNotFoundError,
        ParamFileError,
        RobotLabError,
    )
    from robot_lab.pkg.index import find_executable, package_prefix, package_share
    from robot_lab.rclpy_session import Session, session
    from robot_lab.sim.control import bridge_hint, gz_topics, world_control
    from robot_lab.sim.markers import world_markers
    from robot_lab.sim.sim_view import sim_view
    from robot_lab.sim.simulation import Simulation
    from robot_lab.sim.trial import Trial
    from robot_lab.sim.trial_result import TrialResult
    from robot_lab.tf2.listener import tf_buffer
    from robot_lab.tf2.view_frames import frames_figure, view_frames
