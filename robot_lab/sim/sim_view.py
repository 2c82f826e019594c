"""A running simulation in the notebook's 3D view: `robot_lab.sim_view('room.sdf')`.

Gazebo's GUI draws the world, the robot and its sensors; the kit has one 3D view, RViz's
(`scene_view`), which draws what ROS carries. So the world's shapes come from its SDF file
(`world_markers`, in the odometry frame: the robot's spawn pose is its origin), and the robot
and its scan come as in RViz, from what the bridge and robot_state_publisher publish:
/robot_description, /tf (odom → base_link from DiffDrive's bridged TF), /scan. Nothing here
talks to the simulator: a view of a world on a real Gazebo machine looks the same.
"""

from __future__ import annotations

from pathlib import Path

from robot_lab.scene.camera import extent, overview
from robot_lab.scene.view import SceneView
from robot_lab.sim.markers import world_markers
from robot_lab.sim.simulation import Simulation

__all__ = ['sim_view']


def sim_view(world: str | Path, fixed_frame: str = 'odom', scan: str | None = '/scan',
             origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
             robot_description: str | None = '/robot_description',
             height: int = 480) -> SceneView:
    """The 3D view of a simulated robot in `world` (a path or a kit world's name, as
    `gz sim` takes it): the world's walls and obstacles, the robot, its `scan` topic.

    `origin` is where the robot was spawned (x, y, yaw, as `create -x -y -Y`): DiffDrive's
    odom frame starts there, so the world is drawn shifted by it. The topics need the
    bridge (`/scan`, the model's tf as `/tf`) and robot_state_publisher; until they publish,
    the view's status line says what it waits for. The camera starts above and behind the
    world, all of it in sight (`view.look_at` moves it).
    """
    # the server already printed the world's warnings: loading it again is silent
    shapes = world_markers(Simulation(world, warn=lambda _line: None), fixed_frame, origin)
    view = SceneView(fixed_frame, robot_description=robot_description, height=height)
    box = extent(view.show_markers('world', shapes))
    if box is not None:
        view.look_at(*overview(*box))
    if scan:
        view.add(scan, 'LaserScan')
    return view
