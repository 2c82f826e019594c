"""The simulator as a Gazebo lab runs it: real processes, real ROS messages through the bridge.

`ros2 launch ros_gz_sim gz_sim.launch.py gz_args:="-r room.sdf"`, `ros2 run ros_gz_sim
create -file` and `ros2 run ros_gz_bridge parameter_bridge` (arguments and a YAML file, as
the Gazebo docs write both), then /cmd_vel in and /odom, /scan, /clock out, judged in the
simulation's own time (message stamps), never by sleeping.
"""

from __future__ import annotations

import itertools
import math
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import BIN, Proc
from rosutil import Listener

from robot_lab.rclpy_session import session
from robot_lab.sim.sample_robot import diffbot_urdf
from robot_lab.sim.transport import connect

BRIDGE_YAML = """\
- ros_topic_name: "odom"
  gz_topic_name: "/odom"
  ros_type_name: "nav_msgs/msg/Odometry"
  gz_type_name: "gz.msgs.Odometry"
  direction: GZ_TO_ROS
- topic_name: "scan"
  ros_type_name: "sensor_msgs/msg/LaserScan"
  gz_type_name: "gz.msgs.LaserScan"
  direction: GZ_TO_ROS
"""


def _seconds(stamp: Any) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


@pytest.fixture(scope='module')
def simulation(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    folder = tmp_path_factory.mktemp('sim')
    urdf = folder / 'diffbot.urdf'
    urdf.write_text(diffbot_urdf())
    sim = Proc([str(BIN / 'ros2'), 'launch', 'ros_gz_sim', 'gz_sim.launch.py',
                'gz_args:=-r room.sdf'])
    try:
        sim.wait_for(r"robot_lab's simulator .* on MuJoCo .*not Gazebo", timeout=30)
        sim.wait_for(r'Serving partition', timeout=30)
        create = subprocess.run([str(BIN / 'ros2'), 'run', 'ros_gz_sim', 'create', '-file',
                                 str(urdf), '-name', 'diffbot', '-z', '0.051'],
                                capture_output=True, text=True, timeout=60, check=False)
        assert create.returncode == 0, create.stdout + create.stderr
        assert 'Entity creation successful.' in create.stdout
        sim.wait_for(r"Spawned 'diffbot'")
        yield folder
    finally:
        sim.stop()


@pytest.fixture(scope='module')
def bridge(simulation: Path) -> Iterator[Proc]:
    config = simulation / 'bridge.yaml'
    config.write_text(BRIDGE_YAML)
    process = Proc([str(BIN / 'ros2'), 'run', 'ros_gz_bridge', 'parameter_bridge',
                    '/cmd_vel@geometry_msgs/msg/Twist]gz.msgs.Twist',
                    '/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock',
                    '/imu@sensor_msgs/msg/Imu[gz.msgs.IMU',
                    '--ros-args', '-p', f'config_file:={config}'])
    try:
        process.wait_for(r'Creating GZ->ROS Bridge: \[scan \(gz.msgs.LaserScan\)', timeout=30)
        yield process
    finally:
        process.stop()


def test_nothing_is_a_ros_topic_until_the_bridge_makes_it_one(simulation: Path) -> None:
    connection = connect()
    assert connection is not None
    connection.send({'op': 'sub', 'topic': '/scan'})
    frame = connection.receive()  # the simulator does publish its gz topic ...
    connection.close()
    assert frame is not None and frame['type'] == 'gz.msgs.LaserScan'
    assert session().node.count_publishers('/scan') == 0  # ... which no ROS node offers


def test_scan_has_the_urdfs_samples_at_its_rate_and_reads_the_wall(bridge: Proc) -> None:
    scans = Listener('/scan', 'sensor_msgs/msg/LaserScan')
    try:
        messages = [m for _, m in scans.wait_count(3, timeout=20)]
    finally:
        scans.close()
    assert session().node.count_publishers('/scan') == 1
    scan = messages[-1]
    assert len(scan.ranges) == 360 and scan.header.frame_id == 'laser_frame'
    stamps = [_seconds(m.header.stamp) for m in messages]
    assert all(b - a == pytest.approx(0.1, abs=1e-6) for a, b in itertools.pairwise(stamps))
    index = round(-scan.angle_min / scan.angle_increment)  # the beam nearest straight ahead
    ahead = scan.ranges[index] * math.cos(scan.angle_min + index * scan.angle_increment)
    assert ahead == pytest.approx(2.0, abs=0.01)  # the room's north wall, robot at the origin


def _drive_and_measure(linear: float, angular: float) -> tuple[float, float]:
    """Command a speed; once the odometry reports it, how far and how much it turned in
    exactly 2 s of simulated time (odometry stamps, 50 Hz)."""
    from geometry_msgs.msg import Twist

    odom = Listener('/odom', 'nav_msgs/msg/Odometry')
    publisher = session().node.create_publisher(Twist, '/cmd_vel', 10)
    command = Twist()
    command.linear.x, command.angular.z = linear, angular
    try:
        def steady(ms: list[tuple[float, Any]]) -> bool:
            if ms and not (abs(ms[-1][1].twist.twist.linear.x - linear) < 0.01
                           and abs(ms[-1][1].twist.twist.angular.z - angular) < 0.01):
                publisher.publish(command)  # until the bridge's subscription has matched
            return bool(ms) and abs(ms[-1][1].twist.twist.linear.x - linear) < 0.01 and \
                abs(ms[-1][1].twist.twist.angular.z - angular) < 0.01

        first = odom.wait_until(steady, timeout=20, what='steady speed')[-1][1]
        start = _seconds(first.header.stamp)
        last = odom.wait_until(lambda ms: _seconds(ms[-1][1].header.stamp) >= start + 2.0 - 1e-6,
                               timeout=20, what='2 s of simulated time')
        end = next(m for _, m in last if _seconds(m.header.stamp) >= start + 2.0 - 1e-6)
        assert _seconds(end.header.stamp) == pytest.approx(start + 2.0, abs=1e-6)
    finally:
        publisher.publish(Twist())
        session().node.destroy_publisher(publisher)
        odom.close()

    def yaw(m: Any) -> float:
        q = m.pose.pose.orientation
        return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))

    p0, p1 = first.pose.pose.position, end.pose.pose.position
    turn = (yaw(end) - yaw(first) + math.pi) % (2 * math.pi) - math.pi
    return math.hypot(p1.x - p0.x, p1.y - p0.y), turn


def test_half_a_metre_per_second_for_two_seconds_of_sim_time_is_a_metre(bridge: Proc) -> None:
    distance, _ = _drive_and_measure(0.5, 0.0)
    assert distance == pytest.approx(1.0, rel=0.05)


def test_a_quarter_turn(bridge: Proc) -> None:
    _, turn = _drive_and_measure(0.0, math.pi / 4)
    assert turn == pytest.approx(math.pi / 2, abs=0.1)


def test_clock_is_monotonic(bridge: Proc) -> None:
    clock = Listener('/clock', 'rosgraph_msgs/msg/Clock')
    try:
        times = [_seconds(m.clock) for _, m in clock.wait_count(20, timeout=10)]
    finally:
        clock.close()
    assert all(b > a for a, b in itertools.pairwise(times))


def test_the_imu_arrives_as_sensor_msgs_imu(bridge: Proc) -> None:
    imu = Listener('/imu', 'sensor_msgs/msg/Imu')
    try:
        message = imu.wait_count(1, timeout=10)[-1][1]
    finally:
        imu.close()
    assert message.header.frame_id == 'base_link'
    acceleration = message.linear_acceleration
    assert math.sqrt(acceleration.x ** 2 + acceleration.y ** 2 + acceleration.z ** 2) == \
        pytest.approx(9.8, abs=1.0)  # gravity, felt by the accelerometer on the ground
