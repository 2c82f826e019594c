"""*Creating custom msg and srv files* (Jazzy) end to end, in a kit terminal: `ros2 pkg
create --build-type ament_cmake`, the tutorial's edits to CMakeLists.txt and package.xml,
the real `colcon build` (CMake, rosidl, the system compiler) in a shell that only sourced
the venv's bin/activate, then the types from the CLI and from a Python node.
"""

from __future__ import annotations

import os
import re
import subprocess
import textwrap
from pathlib import Path

import pytest
from conftest import BIN, Proc, venv_env

# ros2pkg's ament_cmake/CMakeLists.txt.em for a package without dependencies or node.
JAZZY_CMAKELISTS = """\
cmake_minimum_required(VERSION 3.8)
project(tutorial_interfaces)

if(CMAKE_COMPILER_IS_GNUCXX OR CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  add_compile_options(-Wall -Wextra -Wpedantic)
endif()

# find dependencies
find_package(ament_cmake REQUIRED)
# uncomment the following section in order to fill in
# further dependencies manually.
# find_package(<dependency> REQUIRED)

if(BUILD_TESTING)
  find_package(ament_lint_auto REQUIRED)
  # the following line skips the linter which checks for copyrights
  # comment the line when a copyright and license is added to all source files
  set(ament_cmake_copyright_FOUND TRUE)
  # the following line skips cpplint (only works in a git repo)
  # comment the line when this package is in a git repo and when
  # a copyright and license is added to all source files
  set(ament_cmake_cpplint_FOUND TRUE)
  ament_lint_auto_find_test_dependencies()
endif()

ament_package()
"""

TUTORIAL_CMAKE = """\
find_package(geometry_msgs REQUIRED)
find_package(rosidl_default_generators REQUIRED)

rosidl_generate_interfaces(${PROJECT_NAME}
  "msg/Num.msg"
  "msg/Sphere.msg"
  "srv/AddThreeInts.srv"
  DEPENDENCIES geometry_msgs # Add packages that above messages depend on, in this case """ \
    """geometry_msgs for Sphere.msg
)
"""

TUTORIAL_PACKAGE_XML = """\
  <depend>geometry_msgs</depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
"""

# The tutorial's check, done from Python: a node publishing Num and serving AddThreeInts.
NODE = """\
import rclpy
from rclpy.node import Node

from tutorial_interfaces.msg import Num
from tutorial_interfaces.srv import AddThreeInts


class Both(Node):
    def __init__(self):
        super().__init__('tutorial_node')
        self.pub = self.create_publisher(Num, 'topic', 10)
        self.count = 0
        self.create_timer(0.2, self.tick)
        self.create_service(AddThreeInts, 'add_three_ints', self.add)

    def tick(self):
        self.pub.publish(Num(num=self.count))
        self.count += 1

    def add(self, request, response):
        response.sum = request.a + request.b + request.c
        self.get_logger().info(f'Incoming request a: {request.a} b: {request.b} c: {request.c}')
        return response


rclpy.init()
print('tutorial node up', flush=True)
rclpy.spin(Both())
"""


def terminal(script: str, cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess[str]:
    env = venv_env()
    return subprocess.run(['bash', '-c', script], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout, check=False)


def test_ament_cmake_template_is_jazzys(tmp_path: Path) -> None:
    made = terminal('ros2 pkg create --build-type ament_cmake --license Apache-2.0 '
                    'tutorial_interfaces', tmp_path)
    assert made.returncode == 0, made.stderr
    lines = made.stdout.splitlines()
    assert 'build type: ament_cmake' in lines
    assert lines[-6:] == [
        'creating folder ./tutorial_interfaces',
        'creating ./tutorial_interfaces/package.xml',
        'creating source and include folder',
        'creating folder ./tutorial_interfaces/src',
        'creating folder ./tutorial_interfaces/include/tutorial_interfaces',
        'creating ./tutorial_interfaces/CMakeLists.txt',
    ]
    pkg = tmp_path / 'tutorial_interfaces'
    assert (pkg / 'CMakeLists.txt').read_text() == JAZZY_CMAKELISTS
    xml = (pkg / 'package.xml').read_text()
    assert '  <buildtool_depend>ament_cmake</buildtool_depend>\n\n' \
           '  <test_depend>ament_lint_auto</test_depend>\n' \
           '  <test_depend>ament_lint_common</test_depend>\n\n' \
           '  <export>\n    <build_type>ament_cmake</build_type>\n  </export>\n' in xml
    assert (pkg / 'LICENSE').read_text().lstrip().startswith('Apache License')


def test_custom_msg_and_srv_tutorial(tmp_path: Path, procs: list[Proc]) -> None:
    src = tmp_path / 'ros2_ws' / 'src'
    src.mkdir(parents=True)
    made = terminal('ros2 pkg create --build-type ament_cmake --license Apache-2.0 '
                    'tutorial_interfaces && cd tutorial_interfaces && mkdir msg srv', src)
    assert made.returncode == 0, made.stderr
    pkg = src / 'tutorial_interfaces'
    (pkg / 'msg' / 'Num.msg').write_text('int64 num\n')
    (pkg / 'msg' / 'Sphere.msg').write_text('geometry_msgs/Point center\nfloat64 radius\n')
    (pkg / 'srv' / 'AddThreeInts.srv').write_text('int64 a\nint64 b\nint64 c\n---\nint64 sum\n')
    cmake = (pkg / 'CMakeLists.txt').read_text()
    testing = '\nif(BUILD_TESTING)'
    (pkg / 'CMakeLists.txt').write_text(cmake.replace(testing, '\n' + TUTORIAL_CMAKE + testing))
    xml = (pkg / 'package.xml').read_text()
    lint = '  <test_depend>ament_lint_auto'
    (pkg / 'package.xml').write_text(xml.replace(lint, TUTORIAL_PACKAGE_XML + '\n' + lint))

    ws = tmp_path / 'ros2_ws'
    # As in a student's own terminal: a bare login environment, then only the README's
    # `source .venv/bin/activate` (before, the build needed .venv/setup.bash as well).
    bare = {'HOME': os.environ['HOME'], 'PATH': '/usr/local/bin:/usr/bin:/bin',
            'LANG': 'C.UTF-8', 'TMPDIR': os.environ.get('TMPDIR', '/tmp')}
    built = subprocess.run(
        ['bash', '-c', f'source {BIN / "activate"} && '
         'colcon build --packages-select tutorial_interfaces'],
        cwd=ws, env=bare, capture_output=True, text=True, timeout=900, check=False)
    assert built.returncode == 0, built.stdout + built.stderr
    finished = re.search(r'Finished <<< tutorial_interfaces \[([^\]]+)\]', built.stdout)
    assert finished, built.stdout
    print(f'\ntutorial_interfaces: colcon build took {finished.group(1)}')  # the build time
    stderr_log = ws / 'log' / 'latest_build' / 'tutorial_interfaces' / 'stderr.log'
    assert stderr_log.read_text() == '', 'a real Jazzy build prints nothing on stderr'

    shown = terminal('source install/setup.bash && ros2 interface show tutorial_interfaces/msg/Num'
                     ' && ros2 interface show tutorial_interfaces/msg/Sphere'
                     ' && ros2 interface show tutorial_interfaces/srv/AddThreeInts', ws)
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout == textwrap.dedent("""\
        int64 num
        geometry_msgs/Point center
        \tfloat64 x
        \tfloat64 y
        \tfloat64 z
        float64 radius
        int64 a
        int64 b
        int64 c
        ---
        int64 sum
        """)

    (tmp_path / 'node.py').write_text(NODE)
    env = venv_env()
    node = Proc(['bash', '-c', f'source install/setup.bash && exec python3 {tmp_path / "node.py"}'],
                env=env, cwd=ws)
    procs.append(node)
    node.wait_for('tutorial node up', timeout=60)
    echoed = terminal('source install/setup.bash && '
                      'ros2 topic echo --once /topic tutorial_interfaces/msg/Num', ws, timeout=60)
    assert echoed.returncode == 0, echoed.stderr
    assert re.fullmatch(r'num: \d+\n---\n', echoed.stdout), echoed.stdout
    called = terminal('source install/setup.bash && ros2 service call /add_three_ints '
                      'tutorial_interfaces/srv/AddThreeInts "{a: 1, b: 2, c: 3}"', ws, timeout=60)
    assert called.returncode == 0, called.stderr
    assert 'tutorial_interfaces.srv.AddThreeInts_Response(sum=6)' in called.stdout
    node.wait_for('Incoming request a: 1 b: 2 c: 3')


@pytest.mark.parametrize('build_type', ['cmake'])
def test_plain_cmake_is_refused_with_the_way_out(tmp_path: Path, build_type: str) -> None:
    made = terminal(f'ros2 pkg create --build-type {build_type} cpp_pkg', tmp_path)
    assert made.returncode == 1
    assert "build type 'cmake' (plain CMake, no ament) is not supported" in made.stderr
    assert not (tmp_path / 'cpp_pkg').exists()
