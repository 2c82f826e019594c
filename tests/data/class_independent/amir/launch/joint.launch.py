import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import LogInfo
from launch_ros.actions import Node


def generate_launch_description():
    config = os.path.join(get_package_share_directory('arm_joint'), 'config', 'joint.yaml')
    return LaunchDescription([
        LogInfo(msg=['elbow joint with ', config]),
        Node(package='arm_joint', executable='joint_encoder', name='joint_encoder',
             parameters=[config]),
        Node(package='arm_joint', executable='joint_pd', name='joint_pd',
             parameters=[config]),
        Node(package='arm_joint', executable='joint_motor', name='joint_motor',
             output='screen'),
    ])
