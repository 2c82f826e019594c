# robot_lab's gz_sim.launch.py: upstream's arguments (ros_gz_sim, Jazzy), robot_lab's simulator.
# Upstream runs `gz sim <gz_args>`; here the same arguments go to robot_lab's simulator
# (lib/ros_gz_sim/gz_sim, robot_lab/sim/server.py), which says what it is when it starts.
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('gz_args', default_value='',
                              description='Arguments to be passed to Gazebo Sim'),
        DeclareLaunchArgument('gz_version', default_value='8',
                              description="Gazebo Sim's major version (robot_lab: ignored)"),
        DeclareLaunchArgument('ign_args', default_value='',
                              description='Deprecated: Arguments to be passed to Gazebo Sim'),
        DeclareLaunchArgument('ign_version', default_value='',
                              description="Deprecated: Gazebo Sim's major version"),
        DeclareLaunchArgument('debugger', default_value='false',
                              description='Run in Debugger (robot_lab: not available)'),
        DeclareLaunchArgument('on_exit_shutdown', default_value='false',
                              description='Shutdown on gz-sim exit'),
        Node(package='ros_gz_sim', executable='gz_sim', name='gz_sim', output='screen',
             arguments=[LaunchConfiguration('gz_args'), LaunchConfiguration('ign_args')]),
    ])
