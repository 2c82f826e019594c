"""What a one-shot `ros2` command imports: rclpy's action modules only when it makes an
action client, and never the message code generator (0.05 s of CPU less per command); an
action client made later in the same process is still guarded
(rclpy_session.guard_action_clients)."""

from __future__ import annotations

import subprocess
import sys

PROBE = """
import contextlib, io, sys
from robot_lab.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    main(['node', 'list', '--no-daemon'], prog='ros2')
heavy = ('rclpy.action', 'action_msgs', 'rosidl_generator_py.generate_py_impl', 'em', 'lark')
print(sorted(name for name in heavy if name in sys.modules))
from rclpy.action import ActionClient
import rosidl_generator_py
print(getattr(ActionClient, '_robot_lab_guarded', False), callable(rosidl_generator_py.generate_py))
"""


def test_a_cold_node_list_imports_no_action_module_nor_generator() -> None:
    done = subprocess.run([sys.executable, '-c', PROBE], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ['[]', 'True True'], done.stdout + done.stderr
