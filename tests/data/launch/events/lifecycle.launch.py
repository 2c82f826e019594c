"""launch_ros's lifecycle_pub_sub example, on a Python lifecycle talker: configure from
launch, activate when it reaches 'inactive', log when it is 'active'."""

import sys
from pathlib import Path

import launch
import launch.actions
import launch.events
import launch_ros.actions
import launch_ros.event_handlers
import launch_ros.events.lifecycle
import lifecycle_msgs.msg

TALKER = str(Path(__file__).with_name('lifecycle_talker.py'))


def generate_launch_description():
    talker = launch_ros.actions.LifecycleNode(
        executable=sys.executable, arguments=[TALKER], name='lc_talker', namespace='',
        output='screen')
    auto = launch_ros.actions.LifecycleNode(
        executable=sys.executable, arguments=[TALKER], name='lc_auto', namespace='',
        autostart=True)
    return launch.LaunchDescription([
        launch.actions.RegisterEventHandler(launch_ros.event_handlers.OnStateTransition(
            target_lifecycle_node=talker, goal_state='inactive',
            entities=[
                launch.actions.LogInfo(msg="node 'lc_talker' reached 'inactive', activating"),
                launch.actions.EmitEvent(event=launch_ros.events.lifecycle.ChangeState(
                    lifecycle_node_matcher=launch.events.matches_action(talker),
                    transition_id=lifecycle_msgs.msg.Transition.TRANSITION_ACTIVATE)),
            ])),
        launch.actions.RegisterEventHandler(launch_ros.event_handlers.OnStateTransition(
            target_lifecycle_node=talker, goal_state='active',
            entities=[launch.actions.LogInfo(msg="node 'lc_talker' reached 'active'")])),
        launch.actions.RegisterEventHandler(launch_ros.event_handlers.OnStateTransition(
            target_lifecycle_node=auto, goal_state='active',
            entities=[launch.actions.LogInfo(msg="node 'lc_auto' reached 'active'")])),
        talker,
        auto,
        launch.actions.EmitEvent(event=launch_ros.events.lifecycle.ChangeState(
            lifecycle_node_matcher=launch.events.matches_action(talker),
            transition_id=lifecycle_msgs.msg.Transition.TRANSITION_CONFIGURE)),
    ])
