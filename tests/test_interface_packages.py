"""The tutorials' interface packages, built by the kit from their upstream definitions:
imported as the tutorials write it, shown by `ros2 interface`, and the Python
service/client (AddTwoInts) and action (Fibonacci) tutorials end to end, as a student in a
terminal does them: `ros2 pkg create`, write the nodes, `colcon build`, `ros2 run`.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from conftest import Proc, cli_ok, venv_env

from robot_lab.pkg.kit_packages import KIT_PACKAGES, kit_package_sources

SITE = Path(sys.prefix)


def terminal(script: str, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    """A bash command line in a kit terminal (the venv's bin first on PATH)."""
    env = venv_env()
    return subprocess.run(['bash', '-c', script], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout, check=False)


def test_kit_packages_are_built_from_the_shipped_definitions() -> None:
    for name in KIT_PACKAGES:
        assert (SITE / 'share' / 'ament_index' / 'resource_index' / 'packages' / name).is_file()
    # What rosidl installed is upstream's text, byte for byte.
    spawn = kit_package_sources('turtlesim') / 'srv' / 'Spawn.srv'
    assert (SITE / 'share' / 'turtlesim' / 'srv' / 'Spawn.srv').read_bytes() == spawn.read_bytes()
    assert 'Apache License' in (kit_package_sources('example_interfaces') / 'LICENSE').read_text()


def test_bytecode_beside_a_definition_is_not_an_edit_of_it(tmp_path: Path) -> None:
    """`./kit setup` byte-compiles the venv; a package's sources hashed with their
    __pycache__ would look edited after it, and the package would be built again."""
    from robot_lab.pkg.kit_packages import _source_hash

    (tmp_path / 'launch').mkdir()
    (tmp_path / 'package.xml').write_text('<package/>')
    (tmp_path / 'launch' / 'demo.launch.py').write_text('x = 1\n')
    before = _source_hash(tmp_path)
    (tmp_path / 'launch' / '__pycache__').mkdir()
    (tmp_path / 'launch' / '__pycache__' / 'demo.launch.cpython-311.pyc').write_bytes(b'\0')
    assert _source_hash(tmp_path) == before
    (tmp_path / 'launch' / 'demo.launch.py').write_text('x = 2\n')
    assert _source_hash(tmp_path) != before


def test_imports_as_the_tutorials_write_them(tmp_path: Path) -> None:
    code = textwrap.dedent("""
        from example_interfaces.srv import AddTwoInts
        from action_tutorials_interfaces.action import Fibonacci
        from turtlesim.msg import Pose, Color
        from turtlesim.srv import Spawn, Kill, SetPen, TeleportAbsolute, TeleportRelative
        from turtlesim.action import RotateAbsolute
        print(AddTwoInts.Response(sum=5).sum, Fibonacci.Feedback(partial_sequence=[0, 1]),
              Spawn.Request(x=1.0).x, RotateAbsolute.Goal(theta=1.5).theta)
    """)
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            timeout=60, check=False, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split()[0] == '5'
    assert 'Fibonacci_Feedback(partial_sequence=' in result.stdout


def test_ros2_interface_verbs_know_them() -> None:
    assert cli_ok('interface', 'show', 'turtlesim/srv/Spawn').splitlines() == [
        'float32 x', 'float32 y', 'float32 theta',
        'string name # Optional.  A unique name will be created and returned if this is empty',
        '---', 'string name']
    assert cli_ok('interface', 'package', 'turtlesim').splitlines() == [
        'turtlesim/action/RotateAbsolute', 'turtlesim/msg/Color', 'turtlesim/msg/Pose',
        'turtlesim/srv/Kill', 'turtlesim/srv/SetPen', 'turtlesim/srv/Spawn',
        'turtlesim/srv/TeleportAbsolute', 'turtlesim/srv/TeleportRelative']
    assert '    example_interfaces/srv/AddTwoInts' in cli_ok('interface', 'list').splitlines()
    shown = cli_ok('interface', 'show', 'action_tutorials_interfaces/action/Fibonacci')
    assert shown.splitlines()[0] == 'int32 order'


SERVICE = """\
import rclpy
from rclpy.node import Node

from example_interfaces.srv import AddTwoInts


class MinimalService(Node):

    def __init__(self):
        super().__init__('minimal_service')
        self.srv = self.create_service(AddTwoInts, 'add_two_ints', self.add_two_ints_callback)

    def add_two_ints_callback(self, request, response):
        response.sum = request.a + request.b
        self.get_logger().info('Incoming request\\na: %d b: %d' % (request.a, request.b))
        return response


def main():
    rclpy.init()
    rclpy.spin(MinimalService())
    rclpy.shutdown()
"""

CLIENT = """\
import sys

import rclpy
from rclpy.node import Node

from example_interfaces.srv import AddTwoInts


class MinimalClientAsync(Node):

    def __init__(self):
        super().__init__('minimal_client_async')
        self.cli = self.create_client(AddTwoInts, 'add_two_ints')
        while not self.cli.wait_for_service(timeout_sec=1.0):
            self.get_logger().info('service not available, waiting again...')

    def send_request(self, a, b):
        return self.cli.call_async(AddTwoInts.Request(a=a, b=b))


def main():
    rclpy.init()
    client = MinimalClientAsync()
    a, b = int(sys.argv[1]), int(sys.argv[2])
    future = client.send_request(a, b)
    rclpy.spin_until_future_complete(client, future)
    client.get_logger().info(
        'Result of add_two_ints: for %d + %d = %d' % (a, b, future.result().sum))
    client.destroy_node()
    rclpy.shutdown()
"""

ACTION_SERVER = """\
import time

import rclpy
from rclpy.action import ActionServer
from rclpy.node import Node

from action_tutorials_interfaces.action import Fibonacci


class FibonacciActionServer(Node):

    def __init__(self):
        super().__init__('fibonacci_action_server')
        self._action_server = ActionServer(self, Fibonacci, 'fibonacci', self.execute_callback)

    def execute_callback(self, goal_handle):
        self.get_logger().info('Executing goal...')
        feedback = Fibonacci.Feedback(partial_sequence=[0, 1])
        for i in range(1, goal_handle.request.order):
            feedback.partial_sequence.append(
                feedback.partial_sequence[i] + feedback.partial_sequence[i - 1])
            goal_handle.publish_feedback(feedback)
            time.sleep(0.1)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=feedback.partial_sequence)


def main():
    rclpy.init()
    rclpy.spin(FibonacciActionServer())
"""

ACTION_CLIENT = """\
import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node

from action_tutorials_interfaces.action import Fibonacci


class FibonacciActionClient(Node):

    def __init__(self):
        super().__init__('fibonacci_action_client')
        self._client = ActionClient(self, Fibonacci, 'fibonacci')

    def send_goal(self, order):
        self._client.wait_for_server()
        future = self._client.send_goal_async(
            Fibonacci.Goal(order=order), feedback_callback=self.feedback_callback)
        future.add_done_callback(self.goal_response_callback)

    def goal_response_callback(self, future):
        goal_handle = future.result()
        self.get_logger().info('Goal accepted :)')
        goal_handle.get_result_async().add_done_callback(self.get_result_callback)

    def get_result_callback(self, future):
        self.get_logger().info('Result: {0}'.format(future.result().result.sequence))
        rclpy.shutdown()

    def feedback_callback(self, feedback_msg):
        self.get_logger().info(
            'Received feedback: {0}'.format(feedback_msg.feedback.partial_sequence))


def main():
    rclpy.init()
    client = FibonacciActionClient()
    client.send_goal(10)
    rclpy.spin(client)
"""


@pytest.fixture(scope='module')
def tutorial_ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """py_srvcli and py_action built in one workspace as the two tutorials build them."""
    ws = tmp_path_factory.mktemp('tutorial_ws')
    (ws / 'src').mkdir()
    created = terminal(
        'cd src && ros2 pkg create --build-type ament_python --license Apache-2.0 '
        'py_srvcli --dependencies rclpy example_interfaces && '
        'ros2 pkg create --build-type ament_python --license Apache-2.0 '
        'py_action --dependencies rclpy action_tutorials_interfaces', ws)
    assert created.returncode == 0, created.stdout + created.stderr
    nodes = {
        'py_srvcli': {'service_member_function': ('service', SERVICE),
                      'client_member_function': ('client', CLIENT)},
        'py_action': {'fibonacci_action_server': ('fibonacci_action_server', ACTION_SERVER),
                      'fibonacci_action_client': ('fibonacci_action_client', ACTION_CLIENT)},
    }
    for pkg, modules in nodes.items():
        entries = []
        for module, (executable, code) in modules.items():
            (ws / 'src' / pkg / pkg / f'{module}.py').write_text(code)
            entries.append(f"            '{executable} = {pkg}.{module}:main',\n")
        setup_py = ws / 'src' / pkg / 'setup.py'
        text = setup_py.read_text()
        marker = "        'console_scripts': [\n"
        assert marker in text
        setup_py.write_text(text.replace(marker, marker + ''.join(entries)))
    built = terminal('colcon build', ws)
    assert built.returncode == 0, built.stdout + built.stderr
    return ws


def test_service_and_client_tutorial(tutorial_ws: Path, procs: list[Proc]) -> None:
    """*Writing a simple service and client (Python)*: `ros2 run py_srvcli client 2 3`."""
    env = venv_env()
    service = Proc(['bash', '-c', 'source install/setup.bash && exec ros2 run py_srvcli service'],
                   env=env, cwd=tutorial_ws)
    procs.append(service)
    client = terminal('source install/setup.bash && ros2 run py_srvcli client 2 3',
                      tutorial_ws, timeout=120)
    assert client.returncode == 0, client.stdout + client.stderr
    assert '[minimal_client_async]: Result of add_two_ints: for 2 + 3 = 5' in \
        client.stdout + client.stderr
    service.wait_for(r'\[minimal_service\]: Incoming request')
    service.wait_for(r'^a: 2 b: 3$')
    call = terminal('ros2 service call /add_two_ints example_interfaces/srv/AddTwoInts '
                    '"{a: 40, b: 2}"', tutorial_ws, timeout=120)
    assert call.returncode == 0, call.stdout + call.stderr
    assert 'response:\nexample_interfaces.srv.AddTwoInts_Response(sum=42)' in call.stdout


def test_action_server_and_client_tutorial(tutorial_ws: Path, procs: list[Proc]) -> None:
    """*Writing an action server and client (Python)*, with action_tutorials_interfaces."""
    env = venv_env()
    server = Proc(['bash', '-c', 'source install/setup.bash && '
                   'exec ros2 run py_action fibonacci_action_server'], env=env, cwd=tutorial_ws)
    procs.append(server)
    client = terminal('source install/setup.bash && ros2 run py_action fibonacci_action_client',
                      tutorial_ws, timeout=120)
    out = client.stdout + client.stderr
    assert client.returncode == 0, out
    assert 'Goal accepted :)' in out
    assert "Received feedback: array('i', [0, 1, 1])" in out
    assert "Result: array('i', [0, 1, 1, 2, 3, 5, 8, 13, 21, 34, 55])" in out
    server.wait_for('Executing goal...')
    sent = terminal('ros2 action send_goal --feedback fibonacci '
                    'action_tutorials_interfaces/action/Fibonacci "{order: 3}"',
                    tutorial_ws, timeout=120)
    assert sent.returncode == 0, sent.stdout + sent.stderr
    assert 'Goal accepted with ID:' in sent.stdout
    assert 'Feedback:\n    partial_sequence:\n- 0\n- 1\n- 1\n' in sent.stdout
    assert 'Result:\n    sequence:\n- 0\n- 1\n- 1\n- 2\n' in sent.stdout
    assert 'Goal finished with status: SUCCEEDED' in sent.stdout


def test_an_interface_package_is_built_for_python_alone(tmp_path: Path) -> None:
    """The kit builds the C type supports rclpy loads and leaves out rclcpp's C++ ones (half
    the set-up's build time); a message then still goes through Fast DDS's C type support."""
    from robot_lab.pkg.kit_packages import _build_env, _build_one

    prefix = tmp_path / 'prefix'
    _build_one('action_tutorials_interfaces', prefix, _build_env(SITE), cpp=False)
    libs = {p.name for p in (prefix / 'lib').glob('*.so')}
    for part in ('generator_c', 'typesupport_c', 'typesupport_fastrtps_c',
                 'typesupport_introspection_c', 'generator_py'):
        assert f'libaction_tutorials_interfaces__rosidl_{part}.so' in libs, libs
    assert not [name for name in libs if 'cpp' in name], libs
    site = next((prefix / 'lib').glob('python3*/site-packages'))
    env = dict(os.environ, PYTHONPATH=f'{site}{os.pathsep}{os.environ.get("PYTHONPATH", "")}',
               AMENT_PREFIX_PATH=f'{prefix}{os.pathsep}{SITE}',
               LD_LIBRARY_PATH=f'{prefix / "lib"}{os.pathsep}'
                               f'{os.environ.get("LD_LIBRARY_PATH", "")}')
    code = ('import action_tutorials_interfaces.action as a, rclpy.serialization as s\n'
            f'assert a.__file__.startswith({str(site)!r})\n'
            'goal = a.Fibonacci.Goal(order=7)\n'
            'back = s.deserialize_message(s.serialize_message(goal), a.Fibonacci.Goal)\n'
            'print(back.order)\n')
    done = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,
                          text=True, timeout=120, check=False)
    assert done.returncode == 0 and done.stdout.strip() == '7', done.stderr
