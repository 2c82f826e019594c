"""ExecuteProcess with shell, on_exit (actions and a function), respawn; GroupAction scoping."""

from launch import LaunchDescription
from launch.actions import (
    ExecuteProcess,
    GroupAction,
    LogInfo,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
    Shutdown,
)
from launch.substitutions import LaunchConfiguration


def exit_report(event, context):
    return LogInfo(msg=f'{event.name} ended with {event.returncode}')


def generate_launch_description():
    flaky = ExecuteProcess(cmd=['exit 3'], shell=True, name='flaky', respawn=True,
                           respawn_delay=0.1, respawn_max_retries=1, on_exit=exit_report)
    return LaunchDescription([
        SetLaunchConfiguration('word', 'outer'),
        GroupAction([
            SetLaunchConfiguration('word', 'inner'),
            SetEnvironmentVariable('GREETING', 'scoped'),
            ExecuteProcess(cmd=['echo', 'group sees', LaunchConfiguration('word'),
                                '${GREETING}'], shell=True, name='inside', output='screen'),
        ]),
        ExecuteProcess(cmd=['echo', 'outside sees', LaunchConfiguration('word'),
                            '${GREETING:-unset}'], shell=True, name='outside', output='screen',
                       on_exit=[LogInfo(msg='outside is done')]),
        flaky,
        ExecuteProcess(cmd=['sleep', '30'], name='sleeper',
                       on_exit=[LogInfo(msg='sleeper stopped')]),
        ExecuteProcess(cmd=['sleep 1.5'], shell=True, name='last', on_exit=[Shutdown()]),
    ])
