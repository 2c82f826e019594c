"""robot_lab.sim's physics core without ROS: drive, turn, scan, clock and determinism.

The simulator is stepped directly (as gz-sim's server steps), its published gz messages
collected; the numbers come from the sample robot's known geometry and the room world's
known walls (inner faces 2.0 m from the centre).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import pytest

from robot_lab.sim.markers import world_markers
from robot_lab.sim.sample_robot import WHEEL_RADIUS, diffbot_urdf
from robot_lab.sim.simulation import Simulation
from robot_lab.sim.systems import Lidar
from robot_lab.sim.xml_tree import SimulationError

pytestmark = pytest.mark.no_ros  # the simulator alone: no DDS, no domain

Messages = dict[str, list[dict[str, Any]]]


def _world(world: str = 'room.sdf', seed: int = 0) -> tuple[Simulation, Messages, list[str]]:
    messages: Messages = {}
    warnings: list[str] = []
    sim = Simulation(world, seed=seed, warn=warnings.append,
                     on_publish=lambda topic, kind, msg: messages.setdefault(topic, []).append(msg))
    sim.spawn(diffbot_urdf(), 'diffbot', (0.0, 0.0, WHEEL_RADIUS + 0.001))
    sim.step(200)  # settle on the wheels
    return sim, messages, warnings


def _drive(sim: Simulation, linear: float, angular: float, seconds: float) -> None:
    sim.command('/cmd_vel', {'linear': {'x': linear}, 'angular': {'z': angular}})
    sim.step(round(seconds / sim.info.step))
    sim.command('/cmd_vel', {'linear': {'x': 0.0}, 'angular': {'z': 0.0}})


def _odom(messages: Messages) -> tuple[float, float, float]:
    pose = messages['/odom'][-1]['pose']
    q = pose['orientation']
    yaw = math.atan2(2 * (q['w'] * q['z'] + q['x'] * q['y']), 1 - 2 * (q['y'] ** 2 + q['z'] ** 2))
    return pose['position']['x'], pose['position']['y'], yaw


def test_half_a_metre_per_second_for_two_seconds_is_a_metre_of_odometry() -> None:
    sim, messages, warnings = _world()
    start = _odom(messages)
    _drive(sim, 0.5, 0.0, 2.0)
    x, y, _ = _odom(messages)
    assert x - start[0] == pytest.approx(1.0, rel=0.05)
    assert abs(y) < 0.01
    assert sim.body_pose('diffbot')[0] > 0.85  # the robot itself moved, not only the wheels
    assert warnings == []


def test_a_quarter_turn_on_the_spot() -> None:
    sim, messages, _ = _world()
    _drive(sim, 0.0, math.pi / 4, 2.0)
    sim.step(300)  # come to rest
    assert _odom(messages)[2] == pytest.approx(math.pi / 2, abs=0.1)


def test_the_scan_has_the_urdfs_samples_and_reads_the_wall() -> None:
    sim, messages, _ = _world()
    sim.step(100)
    scan = messages['/scan'][-1]
    assert scan['count'] == 360 and len(scan['ranges']) == 360
    assert scan['header']['frame_id'] == 'laser_frame'
    # the beam nearest straight ahead, its angle known: the north wall's face is 2.0 m away
    index = round((0.0 - scan['angle_min']) / scan['angle_step'])
    angle = scan['angle_min'] + index * scan['angle_step']
    x = sim.body_pose('diffbot')[0]
    assert scan['ranges'][index] * math.cos(angle) == pytest.approx(2.0 - x, abs=0.01)
    # 10 Hz in simulated time: one scan per 100 ms
    stamps = [s['header']['stamp']['sec'] * 10**9 + s['header']['stamp']['nsec']
              for s in messages['/scan']]
    assert {b - a for a, b in itertools.pairwise(stamps)} == {100_000_000}


def test_clock_is_monotonic_and_the_simulations_time() -> None:
    sim, messages, _ = _world()
    times = [c['sim']['sec'] * 10**9 + c['sim']['nsec'] for c in messages['/clock']]
    assert times == sorted(set(times)) and times[-1] == sim.time_ns == 200 * 10**6


def test_the_same_commands_give_the_same_trajectory() -> None:
    runs = []
    for _ in range(2):
        sim, messages, _ = _world()
        _drive(sim, 0.4, 0.3, 1.0)
        _drive(sim, -0.2, -0.5, 0.5)
        runs.append((sim.data.qpos.tobytes(), [m['pose'] for m in messages['/odom']]))
    assert runs[0] == runs[1]


def test_what_the_kit_does_not_simulate_is_one_line_naming_it() -> None:
    urdf = diffbot_urdf().replace(
        '</robot>', '<gazebo><plugin filename="gz-sim-imu-system" name="gz::sim::systems::Imu"/>'
                    '</gazebo>\n<link name="dangling"/><joint name="j" type="revolute">'
                    '<parent link="base_link"/><child link="dangling"/>'
                    '<limit lower="0" upper="1" effort="1" velocity="1"/></joint></robot>')
    warnings: list[str] = []
    sim = Simulation('empty.sdf', warn=warnings.append)
    sim.spawn(urdf, 'bot', source='bot.urdf')
    assert any(w.startswith('bot.urdf:') and "'gz::sim::systems::Imu'" in w for w in warnings)
    assert any("link 'dangling' has no <inertial>" in w for w in warnings)
    with pytest.raises(SimulationError, match="'bot' already exists"):
        sim.spawn(urdf, 'bot')
    with pytest.raises(SimulationError, match='unable to find'):
        Simulation('no_such_world.sdf')


TUTORIAL = Path(__file__).resolve().parents[1] / 'robot_lab/data/ament_packages/urdf_tutorial/urdf'


def test_urdf_tutorials_r2d2_with_package_meshes_stands_on_its_legs() -> None:
    """07-physics.urdf: package:// COLLADA meshes MuJoCo's own loader refuses, converted
    (each a warning naming its link); its collisions hold it on the ground."""
    source = TUTORIAL / '07-physics.urdf'
    warnings: list[str] = []
    sim = Simulation('empty.sdf', warn=warnings.append)
    sim.spawn(source.read_text(), 'r2d2', (0.0, 0.0, 0.7), source=str(source))
    sim.step(1500)
    base = sim.data.xpos[sim.model.body('r2d2::base_link').id]
    assert 0.4 < base[2] < 0.55
    assert any(w.startswith(f'{source}:') and "link 'left_gripper' converted from COLLADA" in w
               for w in warnings)


def test_a_robot_with_no_collision_falls_and_is_told_why() -> None:
    source = TUTORIAL / '01-myfirst.urdf'
    warnings: list[str] = []
    sim = Simulation('empty.sdf', warn=warnings.append)
    sim.spawn(source.read_text(), 'first', (0.0, 0.0, 0.5), source=str(source))
    sim.step(500)
    assert sim.data.xpos[sim.model.body('first::base_link').id][2] < 0
    assert f"{source}:2: robot 'myfirst' has no <collision> in any link" in '\n'.join(warnings)
    assert any("link 'base_link' has no <inertial>" in w for w in warnings)


def test_the_worlds_walls_as_markers_in_the_robots_odometry_frame() -> None:
    sim = Simulation('room.sdf', warn=print)
    sim.spawn(diffbot_urdf(), 'diffbot', (1.0, 0.0, WHEEL_RADIUS), (0.0, 0.0, math.pi / 2))
    markers = world_markers(sim, 'odom', origin=(1.0, 0.0, math.pi / 2))
    assert len(markers) == 4 and {m.type for m in markers} == {1}  # four boxes, no robot
    # the north wall (x = 2.05 in the world) is 1.05 m to the robot's right in its frame
    north = next(m for m in markers if m.scale.x == pytest.approx(0.1)
                 and m.pose.position.y == pytest.approx(-1.05))
    assert north.pose.position.x == pytest.approx(0.0, abs=1e-9)
    assert north.header.frame_id == 'odom' and north.scale.z == pytest.approx(0.5)


def test_the_maze_is_built_from_included_kit_models_at_their_poses() -> None:
    warnings: list[str] = []
    sim = Simulation('maze.sdf', warn=warnings.append)
    assert warnings == [] and sim.info.name == 'maze'
    assert {'wall_0', 'wall_15', 'obstacle'} <= set(sim.info.models)
    sim.spawn(diffbot_urdf(), 'diffbot', (0.5, 0.0, WHEEL_RADIUS + 0.001), (0.0, 0.0, math.pi / 2))
    lidar = next(s for s in sim.systems if isinstance(s, Lidar))
    sim.step(10)
    ranges = lidar.ranges(sim.model, sim.data)
    ahead = ranges[len(ranges) // 2]  # facing +y from x = 0.5: the outer wall's face at 2.95
    assert ahead == pytest.approx(2.95, abs=0.01)


def test_the_imu_feels_gravity_at_rest_and_the_turn_while_turning() -> None:
    sim, messages, _ = _world()
    sim.step(100)
    rest = messages['/imu'][-1]
    assert rest['linear_acceleration']['z'] == pytest.approx(9.8, abs=0.05)  # the world's g
    assert rest['orientation']['w'] == pytest.approx(1.0, abs=1e-3)
    assert rest['header']['frame_id'] == 'base_link'
    sim.command('/cmd_vel', {'linear': {'x': 0.0}, 'angular': {'z': math.pi / 4}})
    sim.step(1000)  # a whole number of IMU periods: the last message is of this very state
    turning = messages['/imu'][-1]
    # the free joint's angular velocity, in base_link's own frame: the IMU's, at its origin
    free = sim.model.joint('diffbot::free').dofadr[0]
    assert turning['angular_velocity']['z'] == pytest.approx(sim.data.qvel[free + 5], abs=1e-9)
    assert turning['angular_velocity']['z'] > 0.6  # turning the commanded way (wheels slip)
    stamps = [m['header']['stamp']['nsec'] for m in messages['/imu'][-3:]]
    assert stamps[1] - stamps[0] == 10_000_000  # 100 Hz in simulated time


ARM = """<robot name="arm">
  <link name="world"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="arm">
    <collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision>
    <inertial><origin xyz="0.2 0 0"/><mass value="0.5"/>
      <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.007" iyz="0" izz="0.007"/></inertial>
  </link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <gazebo>
    <plugin filename="gz-sim-joint-position-controller-system"
            name="gz::sim::systems::JointPositionController">
      <joint_name>shoulder</joint_name><p_gain>2</p_gain><d_gain>0.3</d_gain>
      <i_gain>0.5</i_gain><i_max>1</i_max><i_min>-1</i_min>
    </plugin>
  </gazebo>
</robot>
"""


def test_joint_position_controller_holds_the_commanded_angle() -> None:
    warnings: list[str] = []
    sim = Simulation('empty.sdf', warn=warnings.append)
    sim.spawn(ARM, 'arm')
    assert warnings == []
    assert sim.command('/model/arm/joint/shoulder/0/cmd_pos', {'data': 0.5})
    sim.step(3000)
    shoulder = sim.model.joint('arm::shoulder')
    assert sim.data.qpos[shoulder.qposadr[0]] == pytest.approx(0.5, abs=0.01)
    assert abs(sim.data.qvel[shoulder.dofadr[0]]) < 0.01  # settled there


def test_an_sdf_world_with_a_mesh_and_elements_the_kit_does_not_simulate(
        tmp_path: Path) -> None:
    """A mesh model (an STL beside the world file) collides; an <actor> and a <road> are one
    warning line each, naming the file and line."""
    trimesh = pytest.importorskip('trimesh')
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(tmp_path / 'block.stl')
    world = tmp_path / 'mesh_world.sdf'
    world.write_text("""<?xml version="1.0"?>
<sdf version="1.8">
  <world name="mesh_world">
    <include><uri>model://ground_plane</uri></include>
    <model name="block">
      <static>true</static>
      <pose>2 0 0.5 0 0 0</pose>
      <link name="link">
        <collision name="c"><geometry><mesh><uri>block.stl</uri></mesh></geometry></collision>
      </link>
    </model>
    <actor name="walker"/>
    <road name="street"/>
  </world>
</sdf>
""")
    warnings: list[str] = []
    sim = Simulation(world, warn=warnings.append)
    assert warnings == [f"{world}:12: <actor> in <world> is not supported by robot_lab's "
                        f'simulator; ignored',
                        f"{world}:13: <road> in <world> is not supported by robot_lab's "
                        f'simulator; ignored']
    sim.spawn(diffbot_urdf(), 'diffbot', (0.0, 0.0, WHEEL_RADIUS + 0.001))
    lidar = next(s for s in sim.systems if isinstance(s, Lidar))
    sim.step(10)
    assert lidar.ranges(sim.model, sim.data)[180] == pytest.approx(1.5, abs=0.01)  # its face


def test_lidar_noise_repeats_with_the_seed_and_differs_without_it() -> None:
    noisy = diffbot_urdf().replace(
        '<range><min>0.1</min><max>12.0</max></range>',
        '<range><min>0.1</min><max>12.0</max></range>'
        '<noise><type>gaussian</type><mean>0.0</mean><stddev>0.01</stddev></noise>')

    def scan(seed: int) -> list[float]:
        messages: Messages = {}
        sim = Simulation('room.sdf', seed=seed, warn=print,
                         on_publish=lambda t, k, m: messages.setdefault(t, []).append(m))
        sim.spawn(noisy, 'diffbot', (0.0, 0.0, WHEEL_RADIUS + 0.001))
        sim.step(100)
        return list(messages['/scan'][-1]['ranges'])

    first, again, other = scan(1), scan(1), scan(2)
    assert first == again and first != other
    assert max(abs(a - b) for a, b in zip(first, other, strict=True)) < 0.1  # noise, not walls


def test_a_urdf_mesh_beside_its_file_collides(tmp_path: Path) -> None:
    """A relative mesh filename is read from the URDF file's folder: the box holds the
    link at its half height."""
    trimesh = pytest.importorskip('trimesh')
    trimesh.creation.box(extents=(0.2, 0.2, 0.2)).export(tmp_path / 'block.stl')
    source = tmp_path / 'block.urdf'
    source.write_text("""<?xml version="1.0"?>
<robot name="block">
  <link name="base_link">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="block.stl"/></geometry></collision>
  </link>
</robot>
""")
    sim = Simulation('empty.sdf', warn=lambda line: None)
    sim.spawn(source.read_text(), 'block', (0.0, 0.0, 0.5), source=str(source))
    sim.step(500)
    assert sim.data.xpos[sim.model.body('block::base_link').id][2] == pytest.approx(0.1, abs=0.01)


def test_a_dynamic_sdf_model_falls_and_rests_on_the_ground(tmp_path: Path) -> None:
    """A model without <static> is dynamic (each link free), in a world file or spawned by
    `create -file model.sdf`: dropped from 0.5 m, a 0.2 m crate comes to rest on the floor."""
    crate = ('<model name="{}"><pose>0 0 9 0 0 0</pose><link name="body"><inertial><mass>'
             '2</mass></inertial><collision name="c"><geometry><box><size>0.2 0.2 0.2</size>'
             '</box></geometry></collision></link></model>')
    world = tmp_path / 'drop.sdf'
    world.write_text('<sdf version="1.9"><world name="drop"><include><uri>model://ground_plane'
                     '</uri></include>' + crate.format('first').replace('0 0 9', '1 0 0.5')
                     + '</world></sdf>')
    sim = Simulation(world, warn=print)
    # create's pose replaces the model's own (0 0 9), as gz-sim's create does
    assert sim.spawn_model(f'<sdf version="1.9">{crate.format("second")}</sdf>', '',
                           (-1.0, 0.0, 0.5)) == 'second'
    sim.step(1500)
    heights = [float(sim.data.xpos[sim.model.body(f'{n}::body').id][2])
               for n in ('first', 'second')]
    assert heights == pytest.approx([0.1, 0.1], abs=0.005)
    with pytest.raises(SimulationError, match="'second' already exists"):
        sim.spawn_model(f'<sdf version="1.9">{crate.format("second")}</sdf>')


def test_what_the_world_and_urdf_ask_for_is_simulated_or_said(tmp_path: Path) -> None:
    """Deliver 1's "nothing is silently ignored", for the elements a lab's files carry: a
    link's <gravity>false floats, surface friction and an inertial's pose are used,
    gz-sim's `type="ignored"` physics is quiet, and each of ODE's solver block, a bounce,
    an include's plugin, a kinematic link, ODE contact tuning, a mimic and an unknown
    JointStatePublisher parameter is one line naming its file and line."""
    world = tmp_path / 'lab.sdf'
    world.write_text("""<sdf version="1.9"><world name="lab">
<physics name="1ms" type="ignored"><max_step_size>0.001</max_step_size>
  <real_time_factor>1.0</real_time_factor><ode><solver><iters>50</iters></solver></ode></physics>
<include><uri>model://ground_plane</uri><plugin name="x" filename="y"/></include>
<model name="float"><pose>0 0 1 0 0 0</pose><link name="l"><gravity>false</gravity>
  <inertial><pose>0.1 0 0 0 0 0</pose><mass>1</mass></inertial>
  <collision name="c"><geometry><sphere><radius>0.1</radius></sphere></geometry>
    <surface><friction><ode><mu>0.3</mu></ode></friction><bounce/></surface>
    <laser_retro>1</laser_retro></collision></link></model>
<model name="k"><static>true</static><link name="l"><kinematic>true</kinematic></link></model>
</world></sdf>""")
    warnings: list[str] = []
    sim = Simulation(world, warn=warnings.append)
    assert warnings == [
        f"{world}:3: <ode> solver settings: robot_lab's simulator runs MuJoCo with its own; "
        f'ignored',
        f"{world}:4: <plugin> in <include> is not supported by robot_lab's simulator; ignored",
        f"{world}:8: <surface> <bounce> not supported by robot_lab's simulator (friction is); "
        f'ignored',
        f"{world}:10: <kinematic> links are not supported by robot_lab's simulator; "
        f'simulated as dynamic']
    sim.step(500)
    body = sim.model.body('float::l')
    assert sim.data.xpos[body.id][2] == pytest.approx(1.0, abs=1e-6)  # no gravity on it
    assert list(body.ipos) == pytest.approx([0.1, 0.0, 0.0])
    assert sim.model.geom('float::l::c').friction[0] == pytest.approx(0.3)

    urdf = diffbot_urdf().replace('</robot>', """
  <link name="arm"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="arm_joint" type="revolute"><parent link="base_link"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <dynamics damping="0.7" friction="0.2"/><mimic joint="left_wheel_joint"/></joint>
  <gazebo reference="arm"><gravity>false</gravity><kp>1e6</kp><kd>1</kd></gazebo>
  <gazebo><plugin filename="gz-sim-joint-state-publisher-system"
    name="gz::sim::systems::JointStatePublisher"><update_rate>5</update_rate></plugin></gazebo>
</robot>""")
    source = tmp_path / 'arm.urdf'
    source.write_text(urdf)
    warnings.clear()
    sim.spawn(urdf, 'armbot', (0.0, -1.0, WHEEL_RADIUS + 0.001), source=str(source))
    lines = urdf.splitlines()

    def line(text: str) -> int:
        return next(i for i, t in enumerate(lines, 1) if text in t)

    assert sorted(warnings) == sorted([
        f"{source}:{line('<mimic')}: <mimic> is not simulated by robot_lab's simulator; the "
        f'joint moves on its own',
        f"{source}:{line('<kp>')}: <kp>, <kd>: ODE's contact tuning, which robot_lab's "
        f'simulator (MuJoCo) has no equivalent of; ignored',
        f"{source}:{line('<update_rate>5')}: JointStatePublisher parameter <update_rate> is "
        f"not supported by robot_lab's simulator; ignored"])
    joint = sim.model.joint('armbot::arm_joint')
    assert (joint.damping[0], joint.frictionloss[0]) == pytest.approx((0.7, 0.2))
    assert sim.model.body_gravcomp[sim.model.body('armbot::arm').id] == pytest.approx(1.0)


VEHICLE = """<model name="vehicle_blue">
  <pose>-1 0 0.325 0 0 0</pose>
  <link name="chassis"><pose>-0.15 0 0.175 0 0 0</pose>
    <inertial><mass>1.14</mass><inertia><ixx>0.126</ixx><iyy>0.416</iyy><izz>0.481</izz>
    </inertia></inertial>
    <collision name="c"><geometry><box><size>2 1 0.57</size></box></geometry></collision>
  </link>
  <link name="lidar_link"><pose>0 0 0.5 0 0 0</pose>
    <inertial><mass>0.1</mass></inertial>
    <sensor name="gpu_lidar" type="gpu_lidar"><topic>lidar2</topic><update_rate>10</update_rate>
      <lidar><scan><horizontal><samples>640</samples><min_angle>-1.396263</min_angle>
        <max_angle>1.396263</max_angle></horizontal></scan>
        <range><min>0.08</min><max>10.0</max></range></lidar><alwaysOn>1</alwaysOn></sensor>
  </link>
  <link name="left_wheel"><pose>0.554 0.625 -0.025 -1.5707 0 0</pose>
    <inertial><mass>2</mass><inertia><ixx>0.145</ixx><iyy>0.145</iyy><izz>0.125</izz>
    </inertia></inertial>
    <collision name="c"><geometry><sphere><radius>0.3</radius></sphere></geometry></collision>
  </link>
  <link name="right_wheel"><pose>0.554 -0.625 -0.025 -1.5707 0 0</pose>
    <inertial><mass>2</mass><inertia><ixx>0.145</ixx><iyy>0.145</iyy><izz>0.125</izz>
    </inertia></inertial>
    <collision name="c"><geometry><sphere><radius>0.3</radius></sphere></geometry></collision>
  </link>
  <link name="caster"><pose>-0.957 0 -0.125 0 0 0</pose>
    <collision name="c"><geometry><sphere><radius>0.2</radius></sphere></geometry></collision>
  </link>
  <joint name="lidar_joint" type="fixed"><parent>chassis</parent><child>lidar_link</child></joint>
  <joint name="left_wheel_joint" type="revolute"><parent>chassis</parent><child>left_wheel</child>
    <axis><xyz>0 0 1</xyz><limit><lower>-1.79769e+308</lower><upper>1.79769e+308</upper>
    </limit></axis></joint>
  <joint name="right_wheel_joint" type="revolute"><parent>chassis</parent><child>right_wheel</child>
    <axis><xyz>0 0 1</xyz><limit><lower>-1.79769e+308</lower><upper>1.79769e+308</upper>
    </limit></axis></joint>
  <joint name="caster_wheel" type="ball"><parent>chassis</parent><child>caster</child></joint>
  <plugin filename="libignition-gazebo-diff-drive-system.so"
          name="ignition::gazebo::systems::DiffDrive">
    <left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>
    <wheel_separation>1.25</wheel_separation><wheel_radius>0.3</wheel_radius>
  </plugin>
</model>"""


def test_an_sdf_robot_drives_and_scans_as_in_gazebos_lidar_tutorial(tmp_path: Path) -> None:
    """A world's SDF model with joints, a DiffDrive and a gpu_lidar (the Jazzy tutorial's
    vehicle_blue, in the shape gz-sim's visualize_lidar.sdf writes it) is a robot: its
    lidar2 reads a wall's known distance, cmd_vel drives it; a Fuel include and the ball
    caster are one line each; `create` of the same model places it at create's pose."""
    world = tmp_path / 'lidar_world.sdf'
    world.write_text(f"""<sdf version="1.6"><world name="lidar_world">
<include><uri>model://ground_plane</uri></include>
<include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Playground</uri></include>
<model name="wall"><static>true</static><pose>3 0 0.5 0 0 0</pose><link name="l"><collision
  name="c"><geometry><box><size>0.2 6 1</size></box></geometry></collision></link></model>
{VEHICLE}
</world></sdf>""")
    messages: Messages = {}
    warnings: list[str] = []
    sim = Simulation(world, warn=warnings.append,
                     on_publish=lambda topic, kind, msg: messages.setdefault(topic, []).append(msg))
    lines = world.read_text().splitlines()

    def at(text: str) -> str:
        return f'{world}:{next(i for i, t in enumerate(lines, 1) if text in t)}'

    ball, caster = at('type="ball"'), at('<link name="caster">')
    assert sorted(warnings) == sorted([
        f"{at('fuel.gazebosim.org')}: <include> of 'https://fuel.gazebosim.org/1.0/"
        f"OpenRobotics/models/Playground': robot_lab's simulator does not download models "
        f'(no network); left out. Put the model on GZ_SIM_RESOURCE_PATH and include it as '
        f'model://<name>',
        f"{ball}: ball joint 'caster_wheel' is not supported by robot_lab's "
        f'simulator; its child is fixed and frictionless (a caster)',
        f"{caster}: link 'caster' has no <inertial>; the simulator "
        f'gives it 0.1 kg and 0.0001 kg m² (Gazebo would drop it)'])
    sim.step(500)
    scan = messages['/lidar2'][-1]
    assert len(scan['ranges']) == 640
    assert scan['ranges'][320] == pytest.approx(3.9, abs=0.01)  # lidar at x -1, wall face 2.9
    sim.command('/model/vehicle_blue/cmd_vel', {'linear': {'x': 0.5}})
    sim.step(2000)
    x, y, _ = sim.body_pose('vehicle_blue')
    assert x - -1.15 == pytest.approx(0.9, abs=0.15) and abs(y) < 0.01  # accelerating to 0.5
    assert sim.spawn_model(f'<sdf version="1.6">{VEHICLE}</sdf>', 'second',
                           (0.0, 2.0, 0.325)) == 'second'
    import mujoco

    chassis = sim.model.body('second::chassis').id
    mujoco.mj_forward(sim.model, sim.data)
    assert list(sim.data.xpos[chassis]) == pytest.approx([-0.15, 2.0, 0.5], abs=1e-6)


def test_the_lidar_tutorials_world_runs_with_the_tutorials_names() -> None:
    """`gz sim -r visualize_lidar.sdf` (Jazzy's Gazebo tutorial): the kit's own world of
    that name has vehicle_blue, driven on /model/vehicle_blue/cmd_vel, its lidar on lidar2
    and a post's on lidar, both 640 beams reading the box's faces 3.5 m away."""
    messages: Messages = {}
    warnings: list[str] = []
    sim = Simulation('visualize_lidar.sdf', warn=warnings.append,
                     on_publish=lambda topic, kind, msg: messages.setdefault(topic, []).append(msg))
    assert warnings == [] and sim.info.name == 'visualize_lidar_world'
    sim.step(200)
    for topic in ('/lidar2', '/lidar'):
        ranges = messages[topic][-1]['ranges']
        assert len(ranges) == 640 and ranges[320] == pytest.approx(3.5, abs=0.01), topic
    assert sim.command('/model/vehicle_blue/cmd_vel', {'linear': {'x': 0.5}})
    sim.step(1000)
    assert sim.body_pose('vehicle_blue')[0] > -3.9  # it drives toward the box
