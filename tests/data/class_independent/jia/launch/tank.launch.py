from pathlib import Path

from ament_index_python.packages import get_package_share_path
from launch import LaunchDescription
from launch_ros.actions import Node

PARAMS = get_package_share_path('tank_level') / 'config' / 'tank.yaml'


def generate_launch_description():
    return LaunchDescription([
        Node(package='tank_level', executable=exe, name=exe, parameters=[str(PARAMS)])
        for exe in ('level_gauge', 'pump_pi', 'pump')
    ])
