# robot_lab's gz_server.launch.py: upstream's arguments (ros_gz_sim, Jazzy). Upstream runs its
# gzserver (the world from world_sdf_file or world_sdf_string, unpaused, no GUI) as a process
# or, with use_composition, as a component; here `gzserver` is robot_lab's simulator
# (robot_lab/sim/server.py), always a process: it says so if use_composition is set.
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription

_ARGUMENTS = (
    ('world_sdf_file', '', 'Path to the SDF world file'),
    ('world_sdf_string', '', 'SDF world string'),
    ('container_name', 'ros_gz_container',
     'Name of container that nodes will load in if use composition'),
    ('create_own_container', 'False',
     'Whether we should start our own ROS container when using composition.'),
    ('use_composition', 'False', 'Use composed bringup if True'),
)


def generate_launch_description():
    declared = [DeclareLaunchArgument(name, default_value=default, description=text)
                for name, default, text in _ARGUMENTS]
    server = Node(package='ros_gz_sim', executable='gzserver', output='screen', parameters=[{
        'world_sdf_file': LaunchConfiguration('world_sdf_file'),
        'world_sdf_string': LaunchConfiguration('world_sdf_string'),
        'use_composition': LaunchConfiguration('use_composition')}])
    return LaunchDescription([*declared, server])
