import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    config = os.path.join(
        get_package_share_directory('plant_water'),
        'config',
        'water.yaml'
    )

    soil_probe = Node(
        package='plant_water',
        executable='soil_probe',
        name='soil_probe',
        parameters=[config]
    )
    watering = Node(
        package='plant_water',
        executable='watering',
        name='watering',
        parameters=[config]
    )
    valve = Node(
        package='plant_water',
        executable='valve',
        name='valve'
    )

    return LaunchDescription([soil_probe, watering, valve])
