from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    settings = Path(get_package_share_directory('sonar_bot')) / 'config' / 'settings.yaml'
    nodes = []
    for executable in ['sonar', 'avoider', 'base']:
        nodes.append(Node(package='sonar_bot', executable=executable,
                          parameters=[str(settings)], output='screen'))
    return LaunchDescription(nodes)
