from launch import LaunchDescription


def generate_launch_description():
    settings = {}
    return LaunchDescription([settings['missing']])
