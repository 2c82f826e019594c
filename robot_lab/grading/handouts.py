"""Packages the course hands to students: notebook 08's broken Lab 1.3 package.

`broken_package(workspace)` writes `src/broken_robot`: Lab 1.3's package as students
really get it wrong — the lab's flat parameter file, a package.xml without
`<build_type>`, a node missing from `console_scripts`, a launch file `data_files` never
installs (Chapter 6's `*launch.py` glob on an XML launch file) and a typo in a topic
name. The files are plain text here (not modules of the kit), so the faults stay faults.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ['BROKEN_PACKAGE', 'broken_package']

BROKEN_PACKAGE = 'broken_robot'

_MAIN = """

def main(args=None):
    rclpy.init(args=args)
    node = {cls}()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
"""

_SENSOR = """import random

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32


class SensorNode(Node):
    def __init__(self):
        super().__init__('sensor_node')
        self.declare_parameter('sensor_rate', 10)
        self.declare_parameter('noise_level', 0.1)
        rate = self.get_parameter('sensor_rate').value
        self.noise = self.get_parameter('noise_level').value
        self.pub = self.create_publisher(Float32, '/sensor/temperature', 10)
        self.timer = self.create_timer(1.0 / rate, self.publish_sensor)
        self.get_logger().info(f'Sensor node started (rate: {rate} Hz)')

    def publish_sensor(self):
        msg = Float32()
        msg.data = 22.5 + random.uniform(-self.noise, self.noise)
        self.pub.publish(msg)
""" + _MAIN.format(cls='SensorNode')

_CONTROLLER = """import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32, String


class ControllerNode(Node):
    def __init__(self):
        super().__init__('controller_node')
        self.declare_parameter('control_rate', 20)
        self.declare_parameter('temp_threshold', 25.0)
        rate = self.get_parameter('control_rate').value
        self.threshold = self.get_parameter('temp_threshold').value
        self.temp_sub = self.create_subscription(
            Float32, '/sensor/temperature', self.temp_callback, 10)
        self.status_pub = self.create_publisher(String, '/robot/status', 10)
        self.timer = self.create_timer(1.0 / rate, self.control_loop)
        self.last_temp = 22.0
        self.get_logger().info('Controller node started')

    def temp_callback(self, msg):
        self.last_temp = msg.data

    def control_loop(self):
        status = String()
        state = 'HIGH' if self.last_temp > self.threshold else 'OK'
        status.data = f'{state} (temp: {self.last_temp:.1f}°C)'
        self.status_pub.publish(status)
""" + _MAIN.format(cls='ControllerNode')

_ROBOT = """import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class RobotNode(Node):
    def __init__(self):
        super().__init__('robot_node')
        self.declare_parameter('robot_name', 'my_robot')
        robot_name = self.get_parameter('robot_name').value
        self.status_sub = self.create_subscription(
            String, '/robot/stauts', self.status_callback, 10)
        self.get_logger().info(f'Robot node started: {robot_name}')

    def status_callback(self, msg):
        self.get_logger().info(f'Status: {msg.data}')
""" + _MAIN.format(cls='RobotNode')

_PACKAGE_XML = """<?xml version="1.0"?>
<?xml-model href="http://download.ros.org/schema/package_format3.xsd" schematypens="http://www.w3.org/2001/XMLSchema"?>
<package format="3">
  <name>broken_robot</name>
  <version>0.0.1</version>
  <description>Lab 1.3, as it often comes back: five faults to find</description>
  <maintainer email="you@example.com">Your Name</maintainer>
  <license>MIT</license>

  <buildtool_depend>ament_python</buildtool_depend>

  <depend>rclpy</depend>
  <depend>std_msgs</depend>

  <exec_depend>ros2launch</exec_depend>
</package>
"""

_SETUP_PY = """from glob import glob

from setuptools import setup

package_name = 'broken_robot'

setup(
    name=package_name,
    version='0.0.1',
    packages=[package_name],
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*launch.py')),
        ('share/' + package_name + '/config', glob('config/*')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Your Name',
    maintainer_email='you@example.com',
    description='Lab 1.3, as it often comes back',
    license='MIT',
    entry_points={
        'console_scripts': [
            'sensor_node = broken_robot.sensor_node:main',
            'controller_node = broken_robot.controller_node:main',
        ],
    },
)
"""

_SETUP_CFG = """[develop]
script_dir=$base/lib/broken_robot
[install]
install_scripts=$base/lib/broken_robot
"""

_LAUNCH = """<?xml version="1.0"?>
<launch>
  <arg name="robot_name" default="my_robot"/>
  <node pkg="broken_robot" exec="sensor_node" name="sensor" output="screen">
    <param from="$(find-pkg-share broken_robot)/config/robot_params.yaml"/>
  </node>
  <node pkg="broken_robot" exec="controller_node" name="controller" output="screen">
    <param from="$(find-pkg-share broken_robot)/config/robot_params.yaml"/>
  </node>
  <node pkg="broken_robot" exec="robot_node" name="robot" output="screen">
    <param name="robot_name" value="$(var robot_name)"/>
  </node>
</launch>
"""

_PARAMS = """# Sensor parameters
sensor_rate: 10
noise_level: 0.1
# Controller parameters
control_rate: 20
temp_threshold: 25.0
"""

_FILES = {
    'package.xml': _PACKAGE_XML,
    'setup.py': _SETUP_PY,
    'setup.cfg': _SETUP_CFG,
    'resource/broken_robot': '',
    'broken_robot/__init__.py': '',
    'broken_robot/sensor_node.py': _SENSOR,
    'broken_robot/controller_node.py': _CONTROLLER,
    'broken_robot/robot_node.py': _ROBOT,
    'launch/robot.launch.xml': _LAUNCH,
    'config/robot_params.yaml': _PARAMS,
}


def broken_package(workspace: str | Path) -> Path:
    """Write (or rewrite, undoing any repair) `src/broken_robot` in `workspace`; its path."""
    root = Path(workspace).expanduser() / 'src' / BROKEN_PACKAGE
    for rel, text in _FILES.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding='utf-8')
    return root
