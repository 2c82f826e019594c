"""The turtle demo with turtle2 chasing carrot1, which the fixed_frame_tf2_broadcaster
hangs off turtle1.

robot_lab's stand-in for the tutorial package's launch file; written for the kit.
"""

from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description():
    demo = Path(get_package_share_directory('turtle_tf2_py'), 'launch',
                'turtle_tf2_demo.launch.py')
    return LaunchDescription([
        IncludeLaunchDescription(PythonLaunchDescriptionSource(str(demo)),
                                 launch_arguments={'target_frame': 'carrot1'}.items()),
        Node(package='turtle_tf2_py', executable='fixed_frame_tf2_broadcaster',
             name='fixed_broadcaster'),
    ])
