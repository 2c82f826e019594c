import os
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    share = get_package_share_directory('cpu_fan')
    cfg = os.path.join(share, 'config', 'fan_config.yaml')
    ld = LaunchDescription()
    ld.add_action(Node(package='cpu_fan', executable='cpu_temp', name='cpu_temp',
                       parameters=[cfg]))
    ld.add_action(Node(package='cpu_fan', executable='fan_curve', name='fan_curve',
                       parameters=[cfg]))
    ld.add_action(Node(package='cpu_fan', executable='fan_pwm', name='fan_pwm'))
    return ld
