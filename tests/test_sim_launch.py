"""A Harmonic-style launch file, written as the Gazebo docs write one, runs unchanged.

gz_sim.launch.py included with `gz_args`, robot_state_publisher with `use_sim_time`,
`create -topic robot_description` and parameter_bridge as launch `Node`s (its YAML file
given as the `config_file` parameter): the robot appears, its joints arrive bridged, and
robot_state_publisher's /tf carries the simulation's time, not the wall clock's.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import Proc
from rosutil import Listener, diffbot_launch

LAUNCH = """\
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch_ros.actions import Node


def generate_launch_description():
    pkg_ros_gz_sim = get_package_share_directory('ros_gz_sim')
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, 'diffbot.urdf')) as infp:
        robot_desc = infp.read()

    gz_sim = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(
            os.path.join(pkg_ros_gz_sim, 'launch', 'gz_sim.launch.py')),
        launch_arguments={'gz_args': '-r room.sdf'}.items(),
    )
    robot_state_publisher = Node(
        package='robot_state_publisher',
        executable='robot_state_publisher',
        name='robot_state_publisher',
        output='both',
        parameters=[
            {'use_sim_time': True},
            {'robot_description': robot_desc},
        ]
    )
    spawn = Node(
        package='ros_gz_sim',
        executable='create',
        arguments=['-topic', 'robot_description', '-name', 'diffbot', '-z', '0.051'],
        output='screen',
    )
    bridge = Node(
        package='ros_gz_bridge',
        executable='parameter_bridge',
        parameters=[{
            'config_file': os.path.join(here, 'bridge.yaml'),
        }],
        output='screen'
    )
    return LaunchDescription([gz_sim, bridge, robot_state_publisher, spawn])
"""

BRIDGE_YAML = """\
- ros_topic_name: "clock"
  gz_topic_name: "clock"
  ros_type_name: "rosgraph_msgs/msg/Clock"
  gz_type_name: "gz.msgs.Clock"
  direction: GZ_TO_ROS
- ros_topic_name: "joint_states"
  gz_topic_name: "joint_states"
  ros_type_name: "sensor_msgs/msg/JointState"
  gz_type_name: "gz.msgs.Model"
  direction: GZ_TO_ROS
"""


@pytest.fixture(scope='module')
def launched(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Proc]:
    folder: Path = tmp_path_factory.mktemp('harmonic')
    with diffbot_launch(folder, LAUNCH, BRIDGE_YAML) as process:
        yield process


def test_the_robot_is_spawned_from_robot_description(launched: Proc) -> None:
    launched.wait_for(r'Entity creation successful\.', timeout=40)
    launched.wait_for(r"Spawned 'diffbot' \(5 links\)")


def test_robot_state_publisher_stamps_the_wheels_with_the_simulations_time(
        launched: Proc) -> None:
    joints = Listener('/joint_states', 'sensor_msgs/msg/JointState')
    tf = Listener('/tf', 'tf2_msgs/msg/TFMessage')
    clock = Listener('/clock', 'rosgraph_msgs/msg/Clock')
    try:
        state = joints.wait_count(1, timeout=40)[-1][1]
        assert sorted(state.name) == ['left_wheel_joint', 'right_wheel_joint']
        moving = tf.wait_until(lambda ms: any(t.child_frame_id == 'left_wheel'
                                              for _, m in ms for t in m.transforms),
                               timeout=20, what='the wheels on /tf')
        latest = clock.wait_count(1, timeout=20)[-1][1].clock
    finally:
        joints.close()
        tf.close()
        clock.close()
    stamp = next(t.header.stamp for _, m in moving for t in m.transforms
                 if t.child_frame_id == 'left_wheel')
    # sim time: seconds since the world started, not since 1970
    assert 0 < stamp.sec + stamp.nanosec * 1e-9 <= latest.sec + latest.nanosec * 1e-9 + 1.0
    assert stamp.sec < 600


def test_a_use_sim_time_node_takes_its_time_from_the_bridged_clock(launched: Proc) -> None:
    import threading

    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from robot_lab.rclpy_session import session

    ros = session()
    node = ros.add_node(Node('sim_time_probe', context=ros.context,
                             parameter_overrides=[Parameter('use_sim_time', value=True)]))
    ticked = threading.Event()
    times: list[float] = []

    def tick() -> None:  # a timer in sim time fires only as /clock advances
        times.append(node.get_clock().now().nanoseconds * 1e-9)
        if len(times) >= 3:
            ticked.set()

    timer = node.create_timer(0.1, tick)
    try:
        assert ticked.wait(20), f'no sim-time timer ticks: {times}'
    finally:
        node.destroy_timer(timer)
        ros.remove_node(node)
        node.destroy_node()
    assert 0 < times[0] < times[-1] < 600  # the simulation's seconds, monotonic
