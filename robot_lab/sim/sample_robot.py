"""A small differential-drive robot with a lidar, written as a Gazebo Harmonic lab writes one.

The tests, the bench and the lesson need one robot whose numbers are known (wheel radius,
separation, the lidar's height and beams), described the way the Articulated Robotics and
ros_gz_project_template tutorials describe theirs: URDF links with inertia, continuous wheel
joints, a frictionless caster, and `<gazebo>` tags for the DiffDrive and JointStatePublisher
systems, a `gpu_lidar` and an `imu` sensor.
"""

from __future__ import annotations

__all__ = ['LIDAR_HEIGHT', 'WHEEL_RADIUS', 'WHEEL_SEPARATION', 'diffbot_urdf']

WHEEL_RADIUS = 0.05
WHEEL_SEPARATION = 0.35
CHASSIS = (0.4, 0.3, 0.1)  # x, y, z size of the chassis box
LIDAR_HEIGHT = 0.2  # the lidar's origin above the ground when the robot rests


def _box_inertia(mass: float, x: float, y: float, z: float) -> str:
    return (f'<inertia ixx="{mass * (y * y + z * z) / 12:.6g}" ixy="0" ixz="0" '
            f'iyy="{mass * (x * x + z * z) / 12:.6g}" iyz="0" '
            f'izz="{mass * (x * x + y * y) / 12:.6g}"/>')


def diffbot_urdf(samples: int = 360, update_rate: float = 10.0, name: str = 'diffbot',
                 odom_frequency: float = 50.0) -> str:
    """The robot's URDF text; `samples` beams over a full turn at `update_rate` Hz."""
    r, sep = WHEEL_RADIUS, WHEEL_SEPARATION
    cx, cy, cz = CHASSIS
    # base_link sits at the wheel axles: the wheels touch the ground at z = -r
    lidar_z = LIDAR_HEIGHT - r
    box = f'<box size="{cx} {cy} {cz}"/>'
    chassis_inertia = _box_inertia(1.0, cx, cy, cz)
    small = ('<inertial><mass value="0.05"/>'
             '<inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>')
    wheel_inertia = ('<inertia ixx="0.000152" ixy="0" ixz="0" iyy="0.000152" iyz="0" '
                     'izz="0.00025"/>')
    wheels = ''
    for side, y, roll in (('left', sep / 2, '-1.5707963267948966'),
                          ('right', -sep / 2, '1.5707963267948966')):
        axis = '0 0 1' if side == 'left' else '0 0 -1'
        wheels += f"""
  <link name="{side}_wheel">
    <visual><geometry><cylinder radius="{r}" length="0.04"/></geometry></visual>
    <collision><geometry><cylinder radius="{r}" length="0.04"/></geometry></collision>
    <inertial><mass value="0.2"/>{wheel_inertia}</inertial>
  </link>
  <joint name="{side}_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="{side}_wheel"/>
    <origin xyz="0 {y} 0" rpy="{roll} 0 0"/><axis xyz="{axis}"/>
  </joint>"""
    return f"""<?xml version="1.0"?>
<robot name="{name}">
  <link name="base_link">
    <visual><origin xyz="0 0 {cz / 2}"/><geometry>{box}</geometry></visual>
    <collision><origin xyz="0 0 {cz / 2}"/><geometry>{box}</geometry></collision>
    <inertial><origin xyz="-0.05 0 {cz / 2}"/><mass value="1.0"/>{chassis_inertia}</inertial>
  </link>{wheels}
  <link name="caster">
    <visual><geometry><sphere radius="{r / 2}"/></geometry></visual>
    <collision><geometry><sphere radius="{r / 2}"/></geometry></collision>
    {small}
  </link>
  <joint name="caster_joint" type="fixed">
    <parent link="base_link"/><child link="caster"/><origin xyz="-0.15 0 {-r / 2}"/>
  </joint>
  <link name="laser_frame">
    <visual><geometry><cylinder radius="0.03" length="0.04"/></geometry></visual>
    {small}
  </link>
  <joint name="laser_joint" type="fixed">
    <parent link="base_link"/><child link="laser_frame"/><origin xyz="0 0 {lidar_z}"/>
  </joint>
  <gazebo reference="caster"><mu1>0.0</mu1><mu2>0.0</mu2></gazebo>
  <gazebo>
    <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
      <left_joint>left_wheel_joint</left_joint>
      <right_joint>right_wheel_joint</right_joint>
      <wheel_separation>{sep}</wheel_separation>
      <wheel_radius>{r}</wheel_radius>
      <topic>cmd_vel</topic>
      <odom_topic>odom</odom_topic>
      <frame_id>odom</frame_id>
      <child_frame_id>base_link</child_frame_id>
      <odom_publish_frequency>{odom_frequency}</odom_publish_frequency>
    </plugin>
    <plugin filename="gz-sim-joint-state-publisher-system"
            name="gz::sim::systems::JointStatePublisher">
      <topic>joint_states</topic>
    </plugin>
  </gazebo>
  <gazebo reference="base_link">
    <sensor name="imu" type="imu">
      <always_on>1</always_on>
      <update_rate>100</update_rate>
      <topic>imu</topic>
      <gz_frame_id>base_link</gz_frame_id>
    </sensor>
  </gazebo>
  <gazebo reference="laser_frame">
    <sensor name="laser" type="gpu_lidar">
      <topic>scan</topic>
      <update_rate>{update_rate}</update_rate>
      <gz_frame_id>laser_frame</gz_frame_id>
      <lidar>
        <scan><horizontal>
          <samples>{samples}</samples><min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle>
        </horizontal></scan>
        <range><min>0.1</min><max>12.0</max></range>
      </lidar>
    </sensor>
  </gazebo>
</robot>
"""
