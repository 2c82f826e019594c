"""turtle2 chases `target_frame` (default turtle1): turtlesim, one pose broadcaster per
turtle, and the listener that steers turtle2.

robot_lab's stand-in for the tutorial package's launch file; written for the kit.
"""

from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def pose_broadcaster(name, turtle):
    return Node(package='turtle_tf2_py', executable='turtle_tf2_broadcaster', name=name,
                parameters=[{'turtlename': turtle}])


def generate_launch_description():
    target = DeclareLaunchArgument('target_frame', default_value='turtle1',
                                   description='Target frame name.')
    return LaunchDescription([
        target,
        Node(package='turtlesim', executable='turtlesim_node', name='sim'),
        pose_broadcaster('broadcaster1', 'turtle1'),
        pose_broadcaster('broadcaster2', 'turtle2'),
        Node(package='turtle_tf2_py', executable='turtle_tf2_listener', name='listener',
             parameters=[{'target_frame': LaunchConfiguration('target_frame')}]),
    ])
