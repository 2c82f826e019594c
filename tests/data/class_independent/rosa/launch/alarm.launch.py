from os.path import join

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    config = join(get_package_share_directory('smoke_alarm'), 'config', 'alarm.yaml')
    detector = Node(package='smoke_alarm', executable='smoke_detector',
                    name='smoke_detector', parameters=[config])
    panel = Node(package='smoke_alarm', executable='alarm_panel', name='alarm_panel',
                 parameters=[config], output='screen')
    siren = Node(package='smoke_alarm', executable='siren', name='siren', output='screen')
    return LaunchDescription([detector, panel, siren])
