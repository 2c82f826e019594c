"""The environment robot_lab gives children: ROS wheels' libraries found without a restart.

The wheels' bootstrapper (.pth) re-executes any Python started without its marker. A
re-exec is seen without timing: /proc/<pid>/environ is the environment of the last
execve, so it differs from what the parent passed exactly when the child restarted.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from conftest import run_cli, users_profile

from robot_lab.env import apply_ros_defaults, ros_environment

USER_LIB = '/opt/user/lib'

# Reports the environment the kernel holds for this process, and a real rclpy node's RMW.
CHILD = r"""
import json, rclpy
from rclpy.utilities import get_rmw_implementation_identifier
raw = open('/proc/self/environ', 'rb').read().split(b'\0')
environ = dict(item.decode().split('=', 1) for item in raw if item)
context = rclpy.Context()
rclpy.init(context=context)
node = rclpy.create_node('env_probe', context=context)
print(json.dumps({'environ': environ, 'rmw': get_rmw_implementation_identifier(),
                  'node': node.get_fully_qualified_name()}))
node.destroy_node()
rclpy.shutdown(context=context)
"""


def shell_environment() -> dict[str, str]:
    """What a user's shell has: no bootstrap marker, a library path of its own."""
    env = {k: v for k, v in os.environ.items() if k != '_ROS_WHEELS_BOOTSTRAP_COMPLETE'}
    env['LD_LIBRARY_PATH'] = USER_LIB
    return env


def probe(env: dict[str, str]) -> dict[str, object]:
    done = subprocess.run([sys.executable, '-c', CHILD], env=env, capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def test_child_with_kit_environment_starts_once_with_same_rmw() -> None:
    shell = shell_environment()
    restarted = probe(shell)
    assert restarted['environ'] != shell  # the observation works: this child re-executed

    kit = dict(apply_ros_defaults(dict(shell)))
    child = probe(kit)
    assert child['environ'] == kit  # no re-exec
    assert child['rmw'] == restarted['rmw'] == 'rmw_fastrtps_cpp'
    assert child['node'] == '/env_probe'


def test_user_library_path_is_kept_after_the_wheels() -> None:
    kit = apply_ros_defaults(shell_environment())
    parts = kit['LD_LIBRARY_PATH'].split(os.pathsep)
    assert parts[-1] == USER_LIB
    assert os.path.join(sys.prefix, 'lib') in parts
    assert any(p.endswith('ros_rclpy.libs') for p in parts)
    assert len(parts) == len(set(parts))
    assert dict(apply_ros_defaults(dict(kit))) == dict(kit)  # idempotent


def test_bootstrapped_library_path_is_left_alone() -> None:
    if not os.environ.get('_ROS_WHEELS_BOOTSTRAP_COMPLETE'):
        pytest.skip('this interpreter was not started through the ROS wheels bootstrapper')
    assert ros_environment()['LD_LIBRARY_PATH'] == os.environ['LD_LIBRARY_PATH']


def test_non_python_child_runs_with_kit_environment() -> None:
    kit = ros_environment()
    done = subprocess.run(['/bin/sh', '-c', 'ls / >/dev/null && echo "$LD_LIBRARY_PATH"'],
                          env=kit, capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == kit['LD_LIBRARY_PATH']


def test_fast_dds_errors_go_to_stderr_not_into_a_verbs_output(tmp_path: Path) -> None:
    """Fast DDS prints its own warnings and errors on stdout; there they became part of
    `node list`'s answer (stop 31's CI: a taken shared-memory port). A stale profile file
    in the working folder (Fast DDS reads ./DEFAULT_FASTRTPS_PROFILES.xml after the kit's)
    makes it log errors every time."""
    (tmp_path / 'DEFAULT_FASTRTPS_PROFILES.xml').write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>'
        '<participant profile_name="stale"><rtps><no_such_setting>1</no_such_setting>'
        '</rtps></participant></profiles></dds>\n')
    # A fresh participant, never a daemon's answer.
    listed = run_cli('node', 'list', cwd=tmp_path,
                     env={'ROBOT_LAB_DAEMON_AUTOSTART': '0', 'ROBOT_LAB_NO_DAEMON': '1'})
    assert listed.returncode == 0, listed.stderr
    # the condition did happen
    assert 'XMLPARSER' in listed.stderr and 'no_such_setting' in listed.stderr, listed.stderr
    # nothing but the answer: node names, if a participant left on the domain has nodes
    assert all(line.startswith('/') for line in listed.stdout.splitlines()), listed.stdout


# A listener in one process, a talker in another: the listener says, once it has heard the
# talker, which shared-memory ports it listens on.
TALKER = r"""
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('data_path_talker')
pub = node.create_publisher(String, 'data_path', 10)
node.create_timer(0.05, lambda: pub.publish(String(data='hello')))
rclpy.spin(node)
"""
LISTENER = r"""
import rclpy
from std_msgs.msg import String
from robot_lab.shared_memory import listening_ports
rclpy.init()
node = rclpy.create_node('data_path_listener')
heard = []
node.create_subscription(String, 'data_path', heard.append, 10)
while not heard:
    rclpy.spin_once(node, timeout_sec=1.0)
print(heard[0].data, sorted(listening_ports()), flush=True)
"""


def _data_path(env: dict[str, str]) -> str:
    talker = subprocess.Popen([sys.executable, '-c', TALKER], env=env)
    try:
        done = subprocess.run([sys.executable, '-c', LISTENER], env=env, capture_output=True,
                              text=True, timeout=60)
    finally:
        talker.terminate()
        talker.wait(30)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_the_kits_participants_take_data_by_udp_not_by_a_shared_memory_port(
        tmp_path: Path) -> None:
    """Fast DDS replaces a shared-memory port whose owner misses a one-second health check
    on a crowded host; the owner then never hears a newcomer (s29B1: a lesson's kernel).
    The kit's profile sends data to its participants by UDP, whose socket no one can take
    over: they listen on no shared-memory port, and still hear each other."""
    assert _data_path(ros_environment()) == 'hello []'
    # A profile of the user's own keeps Fast DDS's default: shared-memory ports.
    own = users_profile(tmp_path)
    said = _data_path({**ros_environment(), 'FASTRTPS_DEFAULT_PROFILES_FILE': str(own)})
    assert said.startswith('hello [') and said != 'hello []', said


# A requester whose response reader the server's writer never matches: its request writer
# is transient-local (a volatile reader takes that), its response reader asks for
# transient-local data, which the server's volatile response writer never offers.
LATE_REQUESTER = r"""
import time, warnings, rclpy
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_srvs.srv import Trigger
rclpy.init()
node = rclpy.create_node('late_requester_probe')
answered = []
def answer(request, response):
    answered.append(time.monotonic())
    return response
node.create_service(Trigger, 'probe', answer)
client = node.create_client(Trigger, 'probe', qos_profile=QoSProfile(
    depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL))
client.call_async(Trigger.Request())
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter('always')
    deadline = time.monotonic() + 30
    while not caught and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.1)
    dropped = time.monotonic()
print(f'{dropped - answered[0]:.2f}' if answered else 'unanswered')
print(caught[0].message if caught else 'no warning')
"""


def test_a_service_answer_waits_for_a_requester_seen_late(ros_domain: int) -> None:
    """A request can come before the server has matched its sender's response reader (a
    lost discovery announcement, repeated at the next heartbeat): rmw_fastrtps holds the
    answer for the writer's max_blocking_time, then drops it and the client waits for
    ever (stop 39's and 42's CI, notebook 09). The kit's profile holds it 15 s, not
    Fast DDS's 0.1 s."""
    done = subprocess.run([sys.executable, '-c', LATE_REQUESTER], env=ros_environment(),
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    waited, warning = done.stdout.strip().splitlines()[-2:]
    assert 'client will not receive response' in warning  # the requester never matched
    assert 14.5 <= float(waited) < 30, f'the answer waited {waited} s for the reader'


VENV_BIN = os.path.join(sys.prefix, 'bin')


def test_the_venvs_bin_is_appended_to_a_path_without_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv('PATH', '/usr/local/bin:/usr/bin:/bin')
    env = ros_environment()
    assert env['PATH'] == f'/usr/local/bin:/usr/bin:/bin{os.pathsep}{VENV_BIN}'
    assert ros_environment(env)['PATH'] == env['PATH']  # once, however often applied
    monkeypatch.delenv('PATH')  # unset: the default search path, then the venv's
    assert ros_environment()['PATH'] == f'{os.defpath}{os.pathsep}{VENV_BIN}'


def test_a_path_that_has_the_venvs_bin_keeps_its_order(monkeypatch: pytest.MonkeyPatch) -> None:
    for path in (f'{VENV_BIN}:/usr/bin:/bin', f'/opt/mine/bin:/usr/bin:{VENV_BIN}/:/bin'):
        monkeypatch.setenv('PATH', path)
        assert ros_environment()['PATH'] == path


def test_a_launch_files_xacro_runs_from_a_kernel_without_the_venv_on_path(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`robot_lab.launch('urdf_tutorial', 'display.launch.py', model=...)` in a kernel
    whose PATH lacks the venv's bin: its `xacro` step ran "file not found: xacro"."""
    import tempfile

    from robot_lab.launch.plan import ProcessSpec
    from robot_lab.launch.resolve import describe_launch

    monkeypatch.setattr(tempfile, 'tempdir', str(tmp_path))  # its parameter files
    monkeypatch.setenv('PATH', '/usr/bin:/bin')
    plan = describe_launch('urdf_tutorial', 'display.launch.py',
                           {'model': 'urdf/08-macroed.urdf.xacro'})
    [publisher] = [a for a in plan.actions if isinstance(a, ProcessSpec)
                   and a.label.startswith('robot_state_publisher')]
    params = yaml.safe_load(
        Path(publisher.cmd[publisher.cmd.index('--params-file') + 1]).read_text())
    urdf = params['/**']['ros__parameters']['robot_description']
    assert '<robot name="macroed">' in urdf and '<link name="base_link">' in urdf, urdf[:300]
