import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    params = os.path.join(get_package_share_directory('auto_door'), 'config', 'door.yaml')
    return LaunchDescription([
        Node(
            package='auto_door',
            executable='presence_sensor',
            name='presence_sensor',
            parameters=[params],
        ),
        Node(
            package='auto_door',
            executable='door_logic',
            name='door_logic',
            parameters=[params],
        ),
        Node(
            package='auto_door',
            executable='door_motor',
            name='door_motor',
            output='screen',
        ),
    ])
