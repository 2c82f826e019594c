"""Two turtlesims side by side, /turtlesim1 and /turtlesim2 (the *Launching nodes* tutorial:
`ros2 launch turtlesim multisim.launch.py`), as turtlesim's own launch file starts them."""

from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description():
    return LaunchDescription([
        Node(package='turtlesim', executable='turtlesim_node', namespace=namespace,
             output='screen')
        for namespace in ('turtlesim1', 'turtlesim2')
    ])
