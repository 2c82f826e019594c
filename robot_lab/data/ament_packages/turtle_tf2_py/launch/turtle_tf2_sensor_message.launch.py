"""The message-filter page's scene: turtlesim, pose frames for turtle1 and turtle3, and
turtle3 driving circles while its position goes out as a PointStamped.

robot_lab's stand-in for the tutorial package's launch file; written for the kit.
`target_frame` is declared as upstream's file declares it (nothing here reads it).
"""

from launch.actions import DeclareLaunchArgument
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('target_frame', default_value='turtle1',
                              description='Target frame name.'),
        Node(package='turtlesim', executable='turtlesim_node', name='sim', output='screen'),
        *(Node(package='turtle_tf2_py', executable='turtle_tf2_broadcaster', name=name,
               parameters=[{'turtlename': turtle}])
          for name, turtle in (('broadcaster1', 'turtle1'), ('broadcaster2', 'turtle3'))),
        Node(package='turtle_tf2_py', executable='turtle_tf2_message_broadcaster',
             name='message_broadcaster'),
    ])
