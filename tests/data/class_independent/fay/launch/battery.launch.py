import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    config = os.path.join(
        get_package_share_directory('battery_watch'),
        'config',
        'battery.yaml'
    )
    return LaunchDescription([
        Node(
            package='battery_watch',
            executable='battery_sensor',
            name='battery_sensor',
            parameters=[config]
        ),
        Node(
            package='battery_watch',
            executable='return_planner',
            name='return_planner',
            parameters=[config]
        ),
        Node(
            package='battery_watch',
            executable='dock_drive',
            name='dock_drive'
        ),
    ])
