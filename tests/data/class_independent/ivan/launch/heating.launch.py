# Starts the thermometer, the thermostat and the heater with the parameters from heating.yaml
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    defaultParams = os.path.join(get_package_share_directory('room_heat'), 'config',
                                 'heating.yaml')
    params = LaunchConfiguration('params')
    return LaunchDescription([
        DeclareLaunchArgument('params', default_value=defaultParams),
        Node(package='room_heat', executable='thermometer', parameters=[params]),
        Node(package='room_heat', executable='thermostat', parameters=[params]),
        Node(package='room_heat', executable='heater'),
    ])
