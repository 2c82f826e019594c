from launch import LaunchDescription
from launch.substitutions import PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    params = PathJoinSubstitution([FindPackageShare('stick_drive'), 'config', 'stick.yaml'])
    return LaunchDescription([
        Node(package='stick_drive', executable='stick', name='stick', parameters=[params]),
        Node(package='stick_drive', executable='mixer', name='mixer', parameters=[params]),
        Node(package='stick_drive', executable='tracks', name='tracks'),
    ])
