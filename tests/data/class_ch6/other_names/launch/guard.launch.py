import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    params = os.path.join(get_package_share_directory('turtle_guard'), 'config', 'guard.yaml')
    return LaunchDescription([
        Node(package='turtle_guard', executable=exe, parameters=[params], output='screen')
        for exe in ('thermometer', 'fan_logic', 'fan_driver')
    ])
