"""Robot descriptions: URDF read with its lines, forward kinematics, and the programs.

`model` reads a URDF (what urdfdom does for the C++ tools), `kinematics` computes the links'
poses as robot_state_publisher's KDL does, `joints` says which joints a joint state
publisher sets; `state_publisher`, `joint_state_publisher`, `check` and `xacro_command` are
the programs the URDF tutorials run. Only `model` and `kinematics` load here: the node
modules import rclpy.
"""

from robot_lab.urdf.kinematics import Pose, joint_pose, link_poses
from robot_lab.urdf.model import Joint, Link, Robot, load_urdf, parse_urdf

__all__ = ['Joint', 'Link', 'Pose', 'Robot', 'joint_pose', 'link_poses', 'load_urdf',
           'parse_urdf']
