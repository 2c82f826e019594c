# robot_lab's gz_spawn_model.launch.py: upstream's arguments (ros_gz_sim, Jazzy), which run
# `create` with its ROS parameters (world, file, string, topic, name, allow_renaming, x y z
# R P Y), as upstream's does; `create` here is robot_lab's (robot_lab/sim/create.py).
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription

_ARGUMENTS = (('world', '', 'World name'), ('file', '', 'SDF filename'),
              ('model_string', '', 'XML(SDF) string'), ('topic', '', 'Get XML from this topic'),
              ('entity_name', '', 'Name of the entity'),
              ('allow_renaming', 'False', 'Whether the entity allows renaming or not'))


def generate_launch_description():
    declared = [DeclareLaunchArgument(name, default_value=default, description=text)
                for name, default, text in _ARGUMENTS]
    pose = {axis: LaunchConfiguration(axis, default='0.0') for axis in 'xyzRPY'}
    create = Node(package='ros_gz_sim', executable='create', output='screen', parameters=[{
        'world': LaunchConfiguration('world'), 'file': LaunchConfiguration('file'),
        'string': LaunchConfiguration('model_string'), 'topic': LaunchConfiguration('topic'),
        'name': LaunchConfiguration('entity_name'),
        'allow_renaming': LaunchConfiguration('allow_renaming'), **pose}])
    return LaunchDescription([*declared, create])
