"""Manometer, valve control and relief valve, all reading config/cooker.yaml."""
from __future__ import annotations

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node

CONFIG = str(Path(get_package_share_directory('pressure_cooker')) / 'config' / 'cooker.yaml')


def generate_launch_description() -> LaunchDescription:
    names = ('manometer', 'valve_control', 'relief_valve')
    return LaunchDescription(
        [Node(package='pressure_cooker', executable=n, name=n, parameters=[CONFIG])
         for n in names])
