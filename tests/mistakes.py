"""The course's table of mistakes and messages: for every answer cell of 01–08 and 11–13,
what its check says to the released copy (unanswered) and to each plausible wrong answer.

Walked in real kernels by tests/test_mistake_path.py (01–06),
tests/test_mistake_path_capstone.py (07–08), tests/test_mistake_path_tf2.py (11),
tests/test_mistake_path_description.py (12) and tests/test_mistake_path_simulation.py (13),
and, for 01–03, in a real browser by tests/browser/test_browser_mistakes.py. Each regex is
matched against the failing check's two lines (and the details under them).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

__all__ = ['LADDERS', 'Ladder', 'Wrong']


@dataclass(frozen=True)
class Wrong:
    """A plausible wrong answer: what the student did, and what the check must say."""

    mistake: str
    edit: Callable[[str], str]
    says: str  # a regex the failing check's message must match
    rerun: list[str] | None = None  # the cells run before its check, if not the ladder's


def swap(*pairs: str) -> Callable[[str], str]:
    """Replace `old` by `new` for each (old, new) pair; each old must be in the answer."""
    def edit(text_: str) -> str:
        for old, new in zip(pairs[::2], pairs[1::2], strict=True):
            assert old in text_, f'{old!r} is not in the answer'
            text_ = text_.replace(old, new)
        return text_
    return edit


def between_markers(answer: str) -> Callable[[str], str]:
    """Replace what stands between the solution markers by `answer`."""
    def edit(text_: str) -> str:
        begin, end = '### BEGIN SOLUTION\n', '### END SOLUTION'
        assert begin in text_ and end in text_, 'no solution markers in the answer'
        return text_[:text_.index(begin) + len(begin)] + answer + text_[text_.index(end):]
    return edit


def keep(text_: str) -> str:
    return text_


@dataclass(frozen=True)
class Ladder:
    unanswered: str  # what the check says to the released copy
    wrong: list[Wrong]
    rerun: list[str] | None = None  # cells run between answer and check (default: all)


PLACEHOLDER = r'still holds the placeholder `# YOUR CODE HERE`'

# The course's table of mistakes and messages: answer cell -> what its check says to the
# released copy and to each wrong answer. The last step of every ladder is the right answer.
LADDERS: dict[str, Ladder] = {
    'nb01_folders': Ladder(r'missing launch/, config/.*Try: make the missing folders', [
        Wrong('the folders made in the workspace, not the package',
              swap('src/my_robot_system/launch src/my_robot_system/config', 'launch config'),
              r'observed missing launch/, config/'),
        Wrong('only the launch folder',
              swap('src/my_robot_system/launch src/my_robot_system/config',
                   'src/my_robot_system/launch'),
              r'observed missing config/.*mkdir -p'),
    ]),
    'nb01_build_type': Ladder(PLACEHOLDER, [
        Wrong('no <export> around the build type',
              swap('  <export>\n    <build_type>ament_python</build_type>\n  </export>',
                   '  <build_type>ament_python</build_type>'),
              r'ros2 doctor says: .*build_type'),
        Wrong('the build type of a C++ package', swap('>ament_python</build_type>',
                                                      '>ament_cmake</build_type>'),
              r'ros2 doctor says: .*ament_cmake'),
    ]),
    'nb01_setup_py': Ladder(PLACEHOLDER, [
        Wrong('a typo in a console_scripts entry',
              swap("'sensor_node = my_robot_system.sensor_node:main'",
                   "'sensor_node = my_robot_system.sensor_nod:main'"),
              r"declares 'sensor_node = my_robot_system\.sensor_nod:main', not "
              r"'sensor_node = my_robot_system\.sensor_node:main'.*Try: fix that string"),
        Wrong('a missing console_scripts entry',
              swap("            'robot_node = my_robot_system.robot_node:main',\n", ''),
              r"'robot_node = my_robot_system\.robot_node:main' is missing"),
        Wrong('config files not installed',
              swap("        ('share/' + package_name + '/config', glob('config/*')),\n", ''),
              r'expected setup\.py to install launch/\*, config/\*; observed .*config'),
    ]),
    'nb02_sensor': Ladder(PLACEHOLDER, rerun=['nb02-11'], wrong=[
        Wrong('publishes String instead of Float32',
              swap('from std_msgs.msg import Float32', 'from std_msgs.msg import Float32, String',
                   "create_publisher(Float32, '/sensor/temperature'",
                   "create_publisher(String, '/sensor/temperature'",
                   'msg = Float32()\n        msg.data = value',
                   "msg = String()\n        msg.data = f'{value:.2f}'"),
              r'/sensor/temperature carries std_msgs/msg/String, not std_msgs/msg/Float32'
              r'.*Try: publish Float32'),
        Wrong('a typo in the topic name', swap("'/sensor/temperature'", "'/sensor/temprature'"),
              r'nothing is published on /sensor/temperature; there is /sensor/temprature '
              r'\(std_msgs/msg/Float32\).*Try: is /sensor/temprature a typo'),
        Wrong('publishes the number, not a message',
              swap('self.pub.publish(msg)', 'self.pub.publish(value)'),
              r'your node stopped: its callback publish_sensor\(\) raised TypeError.* at '
              r'sensor_node\.py line \d+.*Where in your code.*self\.pub\.publish\(value\)'),
        Wrong('a misspelt message class',
              swap('create_publisher(Float32,', 'create_publisher(Flaot32,'),
              r"NameError: name 'Flaot32' is not defined at sensor_node\.py line \d+"
              r'.*Where in your code.*sensor_node\.py, line \d+, in __init__'),
    ]),
    'nb02_controller': Ladder(PLACEHOLDER, [
        Wrong('never publishes the command', swap('        self.cmd_pub.publish(cmd)\n', ''),
              r'/cmd_vel has a publisher \(controller_node\), but nothing arrived'
              r'.*Try: does your code call publish\(\)'),
        Wrong('drives while HIGH, stops while OK',
              swap('cmd.linear.x = 0.0 if high else self.max_speed',
                   'cmd.linear.x = self.max_speed if high else 0.0'),
              r"the last one was \{'linear': \{'x': 0\.0.*Try: cmd\.linear\.x = max_speed "
              r'while the status is OK'),
    ]),
    'nb02_robot': Ladder(PLACEHOLDER, [
        Wrong('subscribes to a misspelt topic', swap("'/robot/status'", "'/robot/stauts'"),
              r"a log line matching 'Status: OK'; observed no such line within 10 s"
              r".*Try: subscribe to '/robot/status'"),
    ]),
    'nb03_launch_xml': Ladder(PLACEHOLDER, [
        Wrong('the node named after its executable',
              swap('name="robot" output', 'name="robot_node" output'),
              r"observed it starts \[.*\('robot_node', 'robot_node'\)\] as \(exec, name\)"),
        Wrong('the robot without its launch argument',
              swap('    <param name="robot_name" value="$(var robot_name)"/>\n', ''),
              r'the robot gets robot_name from the launch argument; observed its parameters '
              r'are none'),
    ]),
    'nb03_params_yaml': Ladder(PLACEHOLDER, [
        Wrong('no ros__parameters level', swap('  ros__parameters:\n', ''),
              r'robot_params\.yaml accepted by rcl; observed it is refused: .*ros__parameters'),
    ]),
    'nb03_sim_launch': Ladder(PLACEHOLDER, []),
    'nb04_sensor_parameters': Ladder(PLACEHOLDER, [
        Wrong('parameters declared without descriptors',
              swap("self.declare_parameter('sensor_rate', 10, ParameterDescriptor(",
                   "self.declare_parameter('sensor_rate', 10)\n        (ParameterDescriptor("),
              r"/sensor_node sensor_rate described with the range 1 … 50; observed its "
              r"description is '' with no range.*Try: pass ParameterDescriptor"),
        Wrong('a parameter used but never declared',
              swap("self.declare_parameter('noise_level', 0.1, ParameterDescriptor(",
                   '_unused = (ParameterDescriptor('),
              r'ParameterNotDeclaredException.*noise_level.* at sensor_node\.py line \d+'),
        Wrong('an integer range on a double parameter',
              swap('floating_point_range=[FloatingPointRange(from_value=0.0, to_value=5.0)]',
                   'integer_range=[IntegerRange(from_value=0, to_value=5, step=1)]'),
              r'noise_level is of type double, but its range is given as integer_range.*'
              r'Try: a double takes floating_point_range'),
        Wrong('a callback that refuses every set',
              swap('        return SetParametersResult(successful=True)\n        ### END SOLUTION',
                   '        return SetParametersResult()\n        ### END SOLUTION'),
              r'/sensor_node to accept noise_level = 0\.0; observed it refused it without a '
              r'reason: your on-set callback returned a SetParametersResult whose successful is '
              r'False \(its default\).*Try: accept with return '
              r'SetParametersResult\(successful=True\)'),
        Wrong('a callback that returns nothing',
              swap('        return SetParametersResult(successful=True)\n        ### END SOLUTION',
                   '        ### END SOLUTION'),
              r"observed it refused it: 'Callback returned an invalid type' — your on-set "
              r'callback returned no SetParametersResult \(a missing return\).*Try: end the '
              r'callback with return SetParametersResult\(successful=True\)'),
    ]),
    'nb04_controller_parameters': Ladder(PLACEHOLDER, [
        Wrong('a callback that refuses nothing',
              swap('if threshold > 30.0 and speed > 1.0:', 'if False:'),
              r'/controller_node to refuse temp_threshold = 35\.0 with a reason about '
              r'max_speed; observed it accepted it'),
        Wrong('a callback that refuses every set',
              swap('        return SetParametersResult(successful=True)\n        ### END SOLUTION',
                   '        return SetParametersResult()\n        ### END SOLUTION'),
              r'/controller_node to accept max_speed = 1\.5; observed it refused it without a '
              r'reason: .*successful is False \(its default\)'),
        Wrong('a refusal without a reason',
              swap('successful=False,\n                reason=',
                   'successful=False)\n            _unsaid = ('),
              r'/controller_node to refuse temp_threshold = 35\.0 with a reason about max_speed; '
              r"observed it refused it without a reason.*Try: say why: "
              r"SetParametersResult\(successful=False, reason='…'\)"),
        Wrong('a refusal whose reason names the wrong parameter',
              swap("reason=f'max_speed {speed} m/s is too fast while",
                   "reason=f'speed {speed} m/s is too fast while"),
              r"observed it refused it with the reason 'speed 1\.5 m/s is too fast.*Try: name "
              r'max_speed in the reason'),
    ]),
    'nb05_expected': Ladder(r'your expected_nodes filled in; observed expected_nodes is empty', [
        Wrong('executable names instead of node names',
              swap("['/sensor', '/controller', '/robot']",
                   "['/sensor_node', '/controller_node', '/robot_node']"),
              r'observed the graph has /controller, /robot, /sensor.*Try: node names are the '
              r'launch file'),
        Wrong('a type without /msg/', swap("'std_msgs/msg/Float32'", "'std_msgs/Float32'"),
              r'/sensor/temperature of type std_msgs/Float32; observed /sensor/temperature is '
              r'std_msgs/msg/Float32'),
    ]),
    'nb05_wiring': Ladder(r'it raised NotImplementedError.*Where in your code', [
        Wrong('names without their namespace',
              swap("return endpoint.node_namespace.rstrip('/') + '/' + endpoint.node_name",
                   'return endpoint.node_name'),
              r"it returned \(\['sensor'\], \['controller'\]\).*Try: full names"),
    ]),
    'nb06_record': Ladder(r'expected a bag at .*Try: record it first', [
        Wrong('a topic left out of the recording', swap(' /robot/status /cmd_vel', ' /cmd_vel'),
              r'the bag has 0 on /robot/status.*Try: is /robot/status in your `ros2 bag '
              r'record` line'),
    ]),
    'nb06_stopped_at': Ladder(r'your answer is None, not a time in seconds', [
        Wrong('the last stop, not the first',
              swap('stopped_at = next(t for t, v in', 'stopped_at = [t for t, v in',
                   'if v == 0.0)', 'if v == 0.0][-1]'),
              r'observed \d+\.\d\d s is the time of the last match.*Try: take the time'),
    ]),
    'nb07_sensor': Ladder(PLACEHOLDER, [
        Wrong('the wrong topic name', swap("'obstacle_distance'", "'distance'"),
              r'nothing is published on /obstacle_distance; there is /distance'),
    ]),
    'nb07_controller': Ladder(PLACEHOLDER, [
        Wrong('the speed not clamped to max_speed',
              swap('min(max(margin, 0.0), 1.0)', 'max(margin, 0.0)'),
              r'/cmd_vel at 0\.5 m/s for an obstacle at 3\.0 m .*observed within 5 s the last '
              r"one was \{'linear': \{'x': 1\.25"),
    ]),
    'nb07_test': Ladder(PLACEHOLDER, rerun=[], wrong=[  # its check runs colcon test itself
        Wrong('a test that cannot fail',
              between_markers('def test_runs(command_for):\n'
                              '    assert command_for(3.0) is not None\n'),
              r'tests in test/test_controller\.py to fail for a node that never stops.*'
              r'observed they all pass for it.*Try: assert the exact value'),
        Wrong('a wrong expected speed', swap('pytest.approx(0.25)', 'pytest.approx(0.3)'),
              r'observed 1 of 3 failed.*Try: .*disagree.*test_slower_closer'),
        Wrong('only the stop tested',
              between_markers('def test_stops(command_for):\n'
                              '    assert command_for(0.2).linear.x == 0.0\n'),
              r'fail for a node that never drives .*observed they all pass for it'),
    ]),
    'nb07_actuator': Ladder(PLACEHOLDER, [
        Wrong('one decimal instead of two', swap('{msg.linear.x:.2f}', '{msg.linear.x:.1f}'),
              r'a log line matching .*Command: linear.*observed no such line.*Try: log every '
              r'command at INFO'),
    ]),
    'nb07_params': Ladder(PLACEHOLDER, [
        Wrong('a flat file, as Chapter 6 writes it',
              lambda s: '\n'.join(line.strip() for line in s.splitlines()
                                   if 'ros__parameters' not in line and not line.endswith(
                                       ('sensor:', 'controller:', 'actuator:'))) + '\n',
              r'params\.yaml accepted by rcl; observed it is refused'),
    ]),
    'nb07_launch': Ladder(PLACEHOLDER, [
        Wrong('the sensor named after its executable',
              swap('exec="sensor_node" name="sensor"', 'exec="sensor_node" name="sensor_node"'),
              r'<node exec="sensor_node" name="sensor"> in robot\.launch\.xml; observed it has '
              r'sensor_node runs sensor_node.*name= the node name'),
    ]),
    'nb07_setup_py': Ladder(PLACEHOLDER, [
        Wrong('a typo in a console_scripts entry',
              swap("'actuator_node = multi_node_robot.actuator_node:main'",
                   "'actuator_node = multi_node_robot.actuator:main'"),
              r"declares 'actuator_node = multi_node_robot\.actuator:main', not"),
    ]),
    'nb07_readme': Ladder(r'observed it lacks colcon build, ros2 launch multi_node_robot', [
        Wrong('no launch command', swap('ros2 launch multi_node_robot robot.launch.xml', ''),
              r'observed it lacks ros2 launch multi_node_robot'),
    ]),
    'nb08_package_xml': Ladder(r'broken_robot built and installed.*Try: read the build output', [
        Wrong('the build type of a C++ package', swap('>ament_python</build_type>',
                                                      '>ament_cmake</build_type>'),
              r'broken_robot built and installed.*Try: read the build output'),
    ]),
    'nb08_source': Ladder(r'observed the command is empty', [
        Wrong('the forgotten source', swap('source install/setup.bash && ', ''),
              r"it printed .*Package 'broken_robot' not found"),
    ]),
    'nb08_setup_py': Ladder(PLACEHOLDER, [
        Wrong('the forgotten rebuild', keep,
              r'missing lib/broken_robot/robot_node.*Try: a new console script needs a build',
              rerun=[]),
        Wrong('a typo in the new console_scripts entry',
              swap("'robot_node = broken_robot.robot_node:main'",
                   "'robot_node = broken_robot.robot:main'"),
              r"declares 'robot_node = broken_robot\.robot:main', not"),
    ]),
    'nb08_params': Ladder(PLACEHOLDER, [
        Wrong('values under the node, without ros__parameters', swap('  ros__parameters:\n', ''),
              r'robot_params\.yaml accepted by rcl; observed it is refused'),
    ]),
    'nb08_topic': Ladder(r'/robot to subscribe to /robot/status; observed it subscribes to '
                         r'/robot/stauts, not /robot/status \(published by /controller\).*'
                         r"Try: is /robot/stauts a typo\? .*'/robot/status' in the "
                         r'create_subscription in robot_node\.py', [
        Wrong('the fix without a restart', keep,
              r"robot_node\.py says '/robot/status' now, but the running /robot still "
              r'subscribes to /robot/stauts: it started before your fix.*Try: a node runs the '
              r'code it started with: run the cell that restarts the system', rerun=[]),
    ]),
    'nb11_echo': Ladder(r'observed the command is empty', [
        Wrong('a frame name with a leading /', swap('world turtle2', 'world /turtle2'),
              r'still running .*its last line was .*"/turtle2".*cannot start with.*Try: use the '
              r'frame names as view_frames shows them'),
    ]),
    'nb11_static': Ladder(PLACEHOLDER, [
        Wrong('parent and child swapped',
              swap("t.header.frame_id = 'world'\n        t.child_frame_id = transformation[1]",
                   "t.header.frame_id = transformation[1]\n        t.child_frame_id = 'world'"),
              r"observed the transform goes mystaticturtle → world.*Try: header\.frame_id is "
              r"the parent frame \('world'\)"),
        Wrong('roll, pitch and yaw written into the quaternion',
              swap('t.transform.rotation.x = quat[0]\n        t.transform.rotation.y = quat[1]\n'
                   '        t.transform.rotation.z = quat[2]\n'
                   '        t.transform.rotation.w = quat[3]',
                   't.transform.rotation.x = float(transformation[5])\n'
                   '        t.transform.rotation.y = float(transformation[6])\n'
                   '        t.transform.rotation.z = float(transformation[7])'),
              r'rotation \(0\.000, 0\.000, 1\.570, 1\.000\), of length 1\.86\d, not 1: tf2 '
              r'normalises it.*Try: write a unit quaternion: .*quaternion_from_euler'),
    ]),
    'nb11_broadcaster': Ladder(PLACEHOLDER, [
        Wrong('no stamp', swap('        t.header.stamp = self.get_clock().now().to_msg()\n', ''),
              r'at the current time; observed its stamp is 0\.000 s.*Try: stamp each transform '
              r'with the time now'),
        Wrong('the child named by a string, not the parameter',
              swap('t.child_frame_id = self.turtlename', "t.child_frame_id = 'turtlename'"),
              r"no frame 'turtle1' on /tf or /tf_static \(they carry world → turtlename.*Try: is "
              r"'turtlename' meant to be 'turtle1'\?"),
    ]),
    'nb11_lookup': Ladder(r'it raised NotImplementedError.*Try: replace the placeholder', [
        Wrong('no timeout', swap(',\n' + ' ' * 35 + 'timeout=Duration(seconds=1.0))', ')'),
              r'called as the listener starts; observed it raised LookupException: .* does not '
              r'exist.*Try: .*timeout='),
        Wrong('target and source swapped', swap("('turtle2', 'turtle1',", "('turtle1', 'turtle2',"),
              r'observed it returned turtle2 seen from turtle1.*Try: .*the first frame is the '
              r'one you look from'),
    ]),
    'nb11_listener': Ladder(PLACEHOLDER, [
        Wrong('the frames swapped in the lookup',
              swap('lookup_transform(to_frame_rel, from_frame_rel,',
                   'lookup_transform(from_frame_rel, to_frame_rel,'),
              r'turtle2 to drive to within 1 m of turtle1; observed turtle2 (drove away|stayed|'
              r'came).*Try: lookup_transform\(to_frame_rel, from_frame_rel'),
    ]),
    'nb11_carrot': Ladder(PLACEHOLDER, [
        Wrong('w = 0.0 for no rotation', swap('t.transform.rotation.w = 1.0',
                                                't.transform.rotation.w = 0.0'),
              r'rotation \(0\.000, 0\.000, 0\.000, 0\.000\): tf2 ignores it \(TF_NAN_INPUT, '
              r'TF_DENORMALIZED_QUATERNION\)'),
        Wrong('the carrot under world, not turtle1',
              swap("t.header.frame_id = 'turtle1'", "t.header.frame_id = 'world'"),
              r"observed 'carrot1' has the parent 'world', not 'turtle1'.*Try: "
              r"header\.frame_id = 'turtle1'"),
    ]),
    'nb11_time_travel': Ladder(r'it raised NotImplementedError.*Try: replace the placeholder', [
        Wrong('both frames in the past',
              swap("return buffer.lookup_transform_full(\n"
                   "        target_frame='turtle2', target_time=now,\n"
                   "        source_frame='turtle1', source_time=when,\n"
                   "        fixed_frame='world', timeout=Duration(seconds=1.0))",
                   "return buffer.lookup_transform('turtle2', 'turtle1', when,\n"
                   "                                   timeout=Duration(seconds=1.0))"),
              r'observed it returned turtle1 seen from where turtle2 was 5 s ago'),
        Wrong('5 s after 1970, not 5 s ago',
              swap('when = now - Duration(seconds=5.0)', 'when = rclpy.time.Time(seconds=5.0)'),
              r'observed it raised ExtrapolationException: .*past.*Try: '),
    ]),
    # 12: the robot's body (URDF, xacro, tf2 in a package)
    'nb12_urdf': Ladder(PLACEHOLDER, [
        Wrong('the caster on a wheel: a wrong parent link',
              swap('<parent link="base_link"/>\n    <child link="caster"/>',
                   '<parent link="left_wheel"/>\n    <child link="caster"/>'),
              r"observed caster's parent link is 'left_wheel' \(joint 'caster_joint', line \d+\)"
              r'.*Try: in joint .caster_joint., write <parent link="base_link"/>'),
        Wrong('a revolute wheel without limits',
              swap('"right_wheel_joint" type="continuous"', '"right_wheel_joint" type="revolute"'),
              r"check_urdf refuses it: line \d+: joint 'right_wheel_joint' is revolute but has no "
              r'<limit>.*Try: add <limit lower='),
    ]),
    'nb12_caster': Ladder(r'observed caster_to_sensor is None', [
        Wrong('the frames the other way round',
              swap('(0.30, 0.0, 0.12)', '(-0.30, 0.0, -0.12)'),
              r'observed caster_to_sensor = \(-0\.3, 0, -0\.12\).*Try: tf2_echo caster '
              r'temp_sensor_link: the first frame is where you stand'),
        Wrong('centimetres', swap('(0.30, 0.0, 0.12)', '(30, 0, 12)'),
              r'observed caster_to_sensor = \(30, 0, 12\).*Try: read the Translation line'),
    ]),
    'nb12_xacro': Ladder(PLACEHOLDER, [
        Wrong('the macro called once', swap('  <xacro:wheel side="right" y="-0.175"/>\n', ''),
              r'observed the macro is called 1 time\(s\).*Try: call it once per wheel'),
        Wrong('both wheels on one side', swap('y="-0.175"', 'y="0.175"'),
              r"observed joint 'right_wheel_joint' differs from my_robot\.urdf"),
    ]),
    'nb12_odom': Ladder(PLACEHOLDER, [
        Wrong('no stamp: a stamp from the past (1970)',
              swap('        t.header.stamp = self.get_clock().now().to_msg()\n', ''),
              r'observed a stamp \d+\.\d s old .*TF_OLD_DATA.*Try: stamp each transform as you '
              r'send it'),
        Wrong('w left at 1: a quaternion that is not normalised',
              swap('        t.transform.rotation.w = math.cos(self.yaw / 2)\n', ''),
              r'length 1\.\d+: tf2 refuses it \(TF_DENORMALIZED_QUATERNION\).*Try: .*set w too'),
        Wrong('the whole angle, not half',
              swap('math.sin(self.yaw / 2)', 'math.sin(self.yaw)',
                   'math.cos(self.yaw / 2)', 'math.cos(self.yaw)'),
              r'observed base_link faces \d+° away from the way it moves.*Try: .*half the angle'),
    ]),
    'nb12_listener': Ladder(PLACEHOLDER, [
        Wrong('a lookup in __init__, before the transform exists',
              swap('self.on_temperature, 10)\n',
                   "self.on_temperature, 10)\n        self.mount = self.tf_buffer.lookup_transform("
                   "'base_link', 'temp_sensor_link', Time())\n"),
              r'observed LookupException: "base_link" passed to lookupTransform argument '
              r'target_frame does not exist\.\s+at sensor_in_odom\.py line \d+.*Try: nothing has '
              r'arrived while your node is being built .*timeout= cannot help here'),
        Wrong('target and source swapped',
              swap("lookup_transform('odom', 'temp_sensor_link', Time())",
                   "lookup_transform('temp_sensor_link', 'odom', Time())"),
              r"tf2 puts temp_sensor_link at .*Try: lookup_transform\('odom', 'temp_sensor_link'"),
        Wrong('the point left in the sensor frame',
              swap("point.header.frame_id = 'odom'",
                   "point.header.frame_id = 'temp_sensor_link'"),
              r"observed header\.frame_id 'temp_sensor_link'.*Try: the point is in odom"),
    ]),
    # 13: the robot in the simulator (gazebo tags, bridge, a controller against /scan)
    'nb13_gazebo': Ladder(PLACEHOLDER, [
        Wrong("the wheel links for DiffDrive's joints",
              swap('<left_joint>left_wheel_joint</left_joint>',
                   '<left_joint>left_wheel</left_joint>',
                   '<right_joint>right_wheel_joint</right_joint>',
                   '<right_joint>right_wheel</right_joint>'),
              r"observed DiffDrive's left_joint is 'left_wheel', a link, not a joint.*"
              r'Try: DiffDrive turns joints'),
        Wrong('the wheel diameter as its radius',
              swap('<wheel_radius>0.08</wheel_radius>', '<wheel_radius>0.16</wheel_radius>'),
              r'observed <wheel_radius> 0\.16 m \(the wheel cylinders have radius 0\.08\)'),
        Wrong('the lidar on gz topic lidar', swap('<topic>scan</topic>', '<topic>lidar</topic>'),
              r'observed the lidar publishes gz topic lidar.*Try: write <topic>scan</topic>'),
    ]),
    'nb13_bridge': Ladder(PLACEHOLDER, [
        Wrong('scan left out of the bridge',
              swap('- ros_topic_name: "scan"\n  gz_topic_name: "scan"\n'
                   '  ros_type_name: "sensor_msgs/msg/LaserScan"\n'
                   '  gz_type_name: "gz.msgs.LaserScan"\n  direction: GZ_TO_ROS\n', ''),
              r'observed nothing publishes /scan: the simulator publishes gz topic /scan.*'
              r'Try: bridge it with: ros2 run ros_gz_bridge parameter_bridge '
              r'/scan@sensor_msgs/msg/LaserScan\[gz\.msgs\.LaserScan'),
        Wrong('cmd_vel bridged out of the simulation',
              swap('direction: ROS_TO_GZ', 'direction: GZ_TO_ROS'),
              r'observed /cmd_vel is published by ros_gz_bridge, and nothing takes it into the '
              r'simulation.*Try: the bridge runs it the wrong way'),
    ]),
    'nb13_controller': Ladder(PLACEHOLDER, [
        Wrong('ranges[0] taken as straight ahead',
              swap('index = round((0.0 - scan.angle_min) / scan.angle_increment)', 'index = 0'),
              r'with an obstacle 0\.7 m ahead, but slows to 0\.20 for one behind it.*'
              r'Try: ranges\[0\] is the beam at angle_min'),
        Wrong('the increment taken in degrees',
              swap('/ scan.angle_increment)', '/ (scan.angle_increment * 3.14159 / 180))'),
              r'raised IndexError: (list|array) index out of range at stop_at_wall\.py line \d+.*'
              r'Try: angle_min and angle_increment are in radians'),
        Wrong('no clamp', swap('max(0.0, min(self.max_speed, speed))', 'speed'),
              r'observed it drives at 3\.50 m/s with nothing within 4 m.*Try: clamp the speed '
              r'at max_speed'),
    ]),
    'nb13_stop_launch': Ladder(PLACEHOLDER, [
        Wrong('no use_sim_time', swap("        parameters=[{'use_sim_time': True}],\n", ''),
              r'stopped 0\.\d\d m from the wall .*/stop_at_wall runs without use_sim_time.*'
              r"Try: give the Node parameters=\[\{'use_sim_time': True\}\]"),
    ]),
}
