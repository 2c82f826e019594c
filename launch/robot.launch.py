"""The same system as robot.launch.xml, in the Python frontend."""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    params_file = PathJoinSubstitution(
        [FindPackageShare('robot_lab'), 'config', LaunchConfiguration('config_file')]
    )
    return LaunchDescription([
        DeclareLaunchArgument(
            'robot_name', default_value='my_robot',
            description='Name the robot node reports',
        ),
        DeclareLaunchArgument(
            'config_file', default_value='robot_params.yaml',
            description="Parameter file in this package's config/ (nested under ros__parameters)",
        ),
        Node(
            package='robot_lab', executable='sensor_node', name='sensor',
            parameters=[params_file], output='screen',
        ),
        Node(
            package='robot_lab', executable='controller_node', name='controller',
            parameters=[params_file], output='screen',
        ),
        Node(
            package='robot_lab', executable='robot_node', name='robot',
            parameters=[{'robot_name': LaunchConfiguration('robot_name')}], output='screen',
        ),
    ])
