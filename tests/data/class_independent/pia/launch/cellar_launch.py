import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    yaml = os.path.join(get_package_share_directory('dry_cellar'), 'config', 'cellar.yaml')
    nodes = [Node(package='dry_cellar', executable=name, name=name, parameters=[yaml])
             for name in ['hygrometer', 'humidistat', 'dehumidifier']]
    return LaunchDescription(nodes)
