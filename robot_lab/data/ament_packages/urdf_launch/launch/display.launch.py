# robot_lab's urdf_launch display.launch.py: upstream's arguments and description include,
# with the kit's stand-ins for the two desktop programs. joint_state_publisher_gui (Qt) is
# robot_lab.joint_sliders() in a notebook: joint_state_publisher runs for both values of
# jsp_gui and takes the sliders' /joint_sliders as a source, so the two never publish
# /joint_states against each other. RViz's place is robot_lab.scene_view(), whose notebook
# line this launch prints (rviz_config is accepted, as upstream's, and unused).
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, LogInfo
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription


def generate_launch_description():
    ld = LaunchDescription()

    urdf_launch_package = FindPackageShare('urdf_launch')

    ld.add_action(DeclareLaunchArgument(name='jsp_gui', default_value='true',
                                        choices=['true', 'false'],
                                        description='Flag to enable joint_state_publisher_gui'))

    default_rviz_config_path = PathJoinSubstitution([urdf_launch_package, 'config', 'urdf.rviz'])
    ld.add_action(DeclareLaunchArgument(name='rviz_config', default_value=default_rviz_config_path,
                                        description='Absolute path to rviz config file'))

    ld.add_action(IncludeLaunchDescription(
        PathJoinSubstitution([urdf_launch_package, 'launch', 'description.launch.py']),
        launch_arguments={
            'urdf_package': LaunchConfiguration('urdf_package'),
            'urdf_package_path': LaunchConfiguration('urdf_package_path')}.items()
    ))

    ld.add_action(Node(
        package='joint_state_publisher',
        executable='joint_state_publisher',
        parameters=[{'source_list': ['/joint_sliders']}],
    ))
    ld.add_action(LogInfo(
        msg="RViz's view, in a notebook: robot_lab.scene_view(fixed_frame='base_link')",
    ))
    ld.add_action(LogInfo(
        msg="joint_state_publisher_gui's sliders, in a notebook: robot_lab.joint_sliders()",
        condition=IfCondition(LaunchConfiguration('jsp_gui')),
    ))
    return ld
