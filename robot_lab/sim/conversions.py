"""ROS message <-> gz message, for the pairs ros_gz_bridge's README lists that the kit simulates.

gz messages are the simulator's dicts (`systems`: field names of the gz.msgs .proto files);
ROS messages are rclpy's. Each pair converts as ros_gz_bridge's convert functions do: a
gz header's `frame_id` becomes the ROS header's, gz.msgs.Model's joints a JointState,
gz.msgs.Pose_V a TFMessage (each pose's name is the child frame).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ['PAIRS', 'SERVICES', 'control_fields', 'from_gz', 'to_gz',
           'world_control_request']

Gz = dict[str, Any]

# (ROS type, gz type) -> the directions the kit converts: 'ros_to_gz', 'gz_to_ros'
PAIRS: dict[tuple[str, str], set[str]] = {
    ('geometry_msgs/msg/Twist', 'gz.msgs.Twist'): {'ros_to_gz', 'gz_to_ros'},
    ('nav_msgs/msg/Odometry', 'gz.msgs.Odometry'): {'gz_to_ros'},
    ('sensor_msgs/msg/LaserScan', 'gz.msgs.LaserScan'): {'gz_to_ros'},
    ('rosgraph_msgs/msg/Clock', 'gz.msgs.Clock'): {'gz_to_ros'},
    ('sensor_msgs/msg/JointState', 'gz.msgs.Model'): {'gz_to_ros'},
    ('tf2_msgs/msg/TFMessage', 'gz.msgs.Pose_V'): {'gz_to_ros'},
    ('sensor_msgs/msg/Imu', 'gz.msgs.IMU'): {'gz_to_ros'},
    ('std_msgs/msg/Float64', 'gz.msgs.Double'): {'ros_to_gz', 'gz_to_ros'},
}

# ROS service type -> its gz request and reply types (ros_gz_bridge's jazzy README: one)
SERVICES: dict[str, tuple[str, str]] = {
    'ros_gz_interfaces/srv/ControlWorld': ('gz.msgs.WorldControl', 'gz.msgs.Boolean'),
}


def world_control_request(msg: Any) -> tuple[Gz, list[str]]:
    """A ros_gz_interfaces/msg/WorldControl as the kit's control frame (`Server.control`'s
    fields), and the fields set that Gazebo itself does not honour.

    As gz-sim (Harmonic) processes it: `pause` always applies (left out, it runs); steps
    happen only when pausing ("Paused after stepping multi_step"); reset.all and time_only
    rewind; run_to_sim_time runs to that time and pauses; model_only resets and seed
    Gazebo warns about and ignores.
    """
    return control_fields(bool(msg.pause), int(msg.multi_step), bool(msg.step),
                          {'all': msg.reset.all, 'time_only': msg.reset.time_only,
                           'model_only': msg.reset.model_only},
                          int(msg.seed), int(msg.run_to_sim_time.sec) * 1_000_000_000
                          + int(msg.run_to_sim_time.nanosec))


def control_fields(pause: bool, multi_step: int, step: bool, reset: dict[str, Any],
                   seed: int, run_to_ns: int) -> tuple[Gz, list[str]]:
    """WorldControl's fields (from ROS or `gz service`) -> the control frame, and what of
    them is not honoured (by Gazebo either)."""
    steps = (multi_step or (1 if step else 0)) if pause else 0
    frame: Gz = {'pause': pause, 'multi_step': steps,
                 'reset': bool(reset.get('all') or reset.get('time_only'))}
    if run_to_ns:
        frame['run_to_sim_time'] = run_to_ns
    unsupported = [name for name, value in (('reset.model_only', reset.get('model_only')),
                                            ('seed', seed)) if value]
    return frame, unsupported


def _header(msg: Any, gz: Gz) -> None:
    header = gz.get('header', {})
    msg.header.stamp.sec = int(header.get('stamp', {}).get('sec', 0))
    msg.header.stamp.nanosec = int(header.get('stamp', {}).get('nsec', 0))
    msg.header.frame_id = str(header.get('frame_id', ''))


def _vector(target: Any, gz: Gz) -> None:
    target.x, target.y, target.z = (float(gz.get(k, 0.0)) for k in 'xyz')


def _quaternion(target: Any, gz: Gz) -> None:
    _vector(target, gz)
    target.w = float(gz.get('w', 1.0))


def _pose(target: Any, gz: Gz) -> None:
    _vector(target.position, gz.get('position', {}))
    _quaternion(target.orientation, gz.get('orientation', {}))


def _twist(msg: Any, gz: Gz) -> None:
    _vector(msg.linear, gz.get('linear', {}))
    _vector(msg.angular, gz.get('angular', {}))


def _odometry(msg: Any, gz: Gz) -> None:
    _header(msg, gz)
    msg.child_frame_id = str(gz.get('child_frame_id', ''))
    _pose(msg.pose.pose, gz.get('pose', {}))
    _twist(msg.twist.twist, gz.get('twist', {}))


def _scan(msg: Any, gz: Gz) -> None:
    _header(msg, gz)
    msg.angle_min, msg.angle_max = float(gz['angle_min']), float(gz['angle_max'])
    msg.angle_increment = float(gz['angle_step'])
    msg.range_min, msg.range_max = float(gz['range_min']), float(gz['range_max'])
    msg.time_increment = 0.0
    msg.scan_time = 0.0
    msg.ranges = [float(r) for r in gz['ranges']]
    msg.intensities = [float(i) for i in gz.get('intensities', [])]


def _clock(msg: Any, gz: Gz) -> None:
    msg.clock.sec = int(gz['sim']['sec'])
    msg.clock.nanosec = int(gz['sim']['nsec'])


def _joint_state(msg: Any, gz: Gz) -> None:
    _header(msg, gz)
    joints = gz.get('joint', [])
    msg.name = [str(j['name']) for j in joints]
    msg.position = [float(j['axis1']['position']) for j in joints]
    msg.velocity = [float(j['axis1']['velocity']) for j in joints]
    msg.effort = [float(j['axis1']['force']) for j in joints]


def _tf(msg: Any, gz: Gz) -> None:
    from geometry_msgs.msg import TransformStamped

    for pose in gz.get('pose', []):
        transform = TransformStamped()
        _header(transform, pose)
        transform.child_frame_id = str(pose.get('name', ''))
        _vector(transform.transform.translation, pose.get('position', {}))
        _quaternion(transform.transform.rotation, pose.get('orientation', {}))
        msg.transforms.append(transform)


def _imu(msg: Any, gz: Gz) -> None:
    _header(msg, gz)
    _quaternion(msg.orientation, gz.get('orientation', {}))
    _vector(msg.angular_velocity, gz.get('angular_velocity', {}))
    _vector(msg.linear_acceleration, gz.get('linear_acceleration', {}))


_FROM_GZ: dict[str, Callable[[Any, Gz], None]] = {
    'gz.msgs.Twist': _twist, 'gz.msgs.Odometry': _odometry, 'gz.msgs.LaserScan': _scan,
    'gz.msgs.Clock': _clock, 'gz.msgs.Model': _joint_state, 'gz.msgs.Pose_V': _tf,
    'gz.msgs.IMU': _imu,
    'gz.msgs.Double': lambda msg, gz: setattr(msg, 'data', float(gz.get('data', 0.0))),
}


def from_gz(gz_type: str, message_class: Any, gz: Gz) -> Any:
    """A new ROS message of `message_class` from a gz message dict."""
    msg = message_class()
    _FROM_GZ[gz_type](msg, gz)
    return msg


def to_gz(gz_type: str, msg: Any) -> Gz:
    """A gz message dict from a ROS message (the pairs that go ROS -> gz)."""
    if gz_type == 'gz.msgs.Double':
        return {'data': float(msg.data)}
    if gz_type == 'gz.msgs.Twist':
        return {'linear': {k: float(getattr(msg.linear, k)) for k in 'xyz'},
                'angular': {k: float(getattr(msg.angular, k)) for k in 'xyz'}}
    raise KeyError(gz_type)
