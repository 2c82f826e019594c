"""A Python launch file using most of the launch / launch_ros API robot_lab provides."""

import os

from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    IncludeLaunchDescription,
    LogInfo,
    OpaqueFunction,
    SetEnvironmentVariable,
    TimerAction,
)
from launch.conditions import IfCondition, UnlessCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import (
    EnvironmentVariable,
    LaunchConfiguration,
    PathJoinSubstitution,
    PythonExpression,
    TextSubstitution,
)
from launch_ros.actions import Node, PushROSNamespace
from launch_ros.substitutions import FindPackageShare
from launch_xml.launch_description_sources import XMLLaunchDescriptionSource


def make_nodes(context, count):
    n = int(LaunchConfiguration('count').perform(context)) + count
    return [Node(package='robot_lab', executable='robot_node', name=f'opaque_{i}')
            for i in range(n)]


def generate_launch_description():
    here = os.path.dirname(__file__)
    return LaunchDescription([
        DeclareLaunchArgument('use_group', default_value='true', choices=['true', 'false']),
        DeclareLaunchArgument('count', default_value='1'),
        SetEnvironmentVariable('ROBOT_LAB_PY', 'set'),
        GroupAction([
            PushROSNamespace('py'),
            Node(package='robot_lab', executable='sensor_node', name='sensor',
                 parameters=[PathJoinSubstitution([FindPackageShare('robot_lab'), 'config',
                                                   'robot_params.yaml']),
                             {'noise_level': 0.0, 'sensor_rate': LaunchConfiguration('count')}],
                 remappings=[('/sensor/temperature', 'temp')]),
        ], condition=IfCondition(LaunchConfiguration('use_group'))),
        Node(package='robot_lab', executable='robot_node', name='skipped',
             condition=UnlessCondition(LaunchConfiguration('use_group'))),
        ExecuteProcess(cmd=['echo', PythonExpression(['2 * ', LaunchConfiguration('count')]),
                            EnvironmentVariable('ROBOT_LAB_PY')],
                       name='echoer', output='screen'),
        OpaqueFunction(function=make_nodes, args=[1]),
        IncludeLaunchDescription(
            XMLLaunchDescriptionSource(os.path.join(here, 'include_child.launch.xml')),
            launch_arguments={'who': TextSubstitution(text='from_python')}.items()),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(os.path.join(here, 'python_small.launch.py'))),
        TimerAction(period=2.0, actions=[LogInfo(msg='tick')]),
    ])
