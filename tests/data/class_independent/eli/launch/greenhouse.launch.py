import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node

CONFIG = os.path.join(get_package_share_directory('greenhouse'), 'config', 'greenhouse.yaml')


def generate_launch_description():
    return LaunchDescription([
        Node(package='greenhouse', executable='thermo', name='thermo', parameters=[CONFIG]),
        Node(package='greenhouse', executable='vent_logic', name='vent_logic',
             parameters=[CONFIG]),
        Node(package='greenhouse', executable='vent_motor', name='vent_motor',
             output='screen'),
    ])
