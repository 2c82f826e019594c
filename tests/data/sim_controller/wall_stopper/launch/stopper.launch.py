from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        Node(
            package='wall_stopper',
            executable='stopper',
            output='screen',
            parameters=[{'use_sim_time': True, 'stop_distance': 0.3}],
        ),
    ])
