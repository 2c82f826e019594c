"""The Jazzy "Using event handlers" tutorial's shape, on the kit's sensor node."""

import sys

from launch import LaunchDescription
from launch.actions import (
    EmitEvent,
    ExecuteProcess,
    LogInfo,
    RegisterEventHandler,
    TimerAction,
)
from launch.event_handlers import (
    OnExecutionComplete,
    OnProcessExit,
    OnProcessIO,
    OnProcessStart,
    OnShutdown,
)
from launch.events import Shutdown
from launch.substitutions import EnvironmentVariable, LocalSubstitution
from launch_ros.actions import Node


def generate_launch_description():
    sensor = Node(package='robot_lab', executable='sensor_node', name='sensor')
    greet = ExecuteProcess(
        cmd=[sys.executable, '-c', 'print("spawned turtle2", flush=True)'], name='greet')
    return LaunchDescription([
        sensor,
        RegisterEventHandler(OnProcessStart(
            target_action=sensor,
            on_start=[LogInfo(msg='Sensor started, greeting'), greet])),
        RegisterEventHandler(OnProcessIO(
            target_action=greet,
            on_stdout=lambda event: LogInfo(
                msg='Greet says "{}"'.format(event.text.decode().strip())))),
        RegisterEventHandler(OnExecutionComplete(
            target_action=greet,
            on_completion=[LogInfo(msg='Greet finished')])),
        # once the node says it runs (and greet is done), end the launch as the tutorial's
        # closed window does, a moment later through a timer
        RegisterEventHandler(OnProcessIO(
            target_action=sensor,
            on_stderr=lambda event: TimerAction(period=0.2, actions=[
                EmitEvent(event=Shutdown(reason='Window closed'))])
            if b'Sensor node started' in event.text else None)),
        RegisterEventHandler(OnProcessExit(
            target_action=sensor,
            on_exit=[LogInfo(msg=(EnvironmentVariable(name='TEST_USER'),
                                  ' closed the sensor'))])),
        RegisterEventHandler(OnShutdown(
            on_shutdown=[LogInfo(
                msg=['Launch was asked to shutdown: ', LocalSubstitution('event.reason')])])),
    ])
