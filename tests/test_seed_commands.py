"""The labs' own commands, typed as the seeds write them, work in the kit's venv.

Lab 1.3 Part 7 (`colcon build`, `source install/setup.bash`,
`ros2 launch … robot_name:=robot_alpha`)
and Part 9 (`ros2 node list`, `ros2 topic list`, `ros2 topic echo`, `ros2 param list`), run
through bash with the venv activated, exactly as a student types them.
"""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

from conftest import BIN


def _bash(script: str, cwd: Path, timeout: float = 60.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ['bash', '-c', f'source {BIN}/activate && source install/setup.bash && {script}'],
        cwd=cwd, capture_output=True, text=True, timeout=timeout, check=False,
        env=dict(os.environ),
    )


def test_lab13_part7_and_part9_as_written(start, seed_workspaces) -> None:
    ws = seed_workspaces.fixed
    launch = start('bash', '-c', f'source {BIN}/activate && source install/setup.bash && '
                   'exec ros2 launch my_robot_system robot.launch.xml robot_name:=robot_alpha',
                   cwd=ws)
    launch.wait_for(r'\[sensor\]: Sensor node started \(rate: 10 Hz\)')
    launch.wait_for(r'\[controller\]: Controller node started')
    launch.wait_for(r'\[robot\]: Robot node started: robot_alpha')
    launch.wait_for(r'\[robot\]: Status: OK \(temp: 22\.\d°C\)')

    nodes = _bash('ros2 node list', ws)
    assert nodes.returncode == 0, nodes.stderr
    assert nodes.stdout.split() == ['/controller', '/robot', '/sensor']

    topics = _bash('ros2 topic list', ws)
    for name in ('/sensor/temperature', '/robot/status', '/parameter_events'):
        assert name in topics.stdout.split(), topics.stdout

    echo = _bash('ros2 topic echo /sensor/temperature --once', ws)
    assert echo.returncode == 0, echo.stderr
    value = float(echo.stdout.split('data:')[1].split()[0])
    assert 22.4 - 1e-3 <= value <= 22.6 + 1e-3
    assert echo.stdout.rstrip().endswith('---')

    # ros2cli prints the `/sensor:` header only when listing every node.
    params = _bash('ros2 param list /sensor', ws)
    assert '  noise_level' in params.stdout.splitlines(), params.stdout
    assert '  sensor_rate' in params.stdout.splitlines()
    every = _bash('ros2 param list', ws)
    assert '/sensor:' in every.stdout.splitlines(), every.stdout

    # The seed's nodes do not catch KeyboardInterrupt, so their Ctrl-C tracebacks are
    # real (a real ros2 launch shows them too); the launcher itself exits cleanly. Ctrl-C
    # alone, waited for as long as launch's own escalation can take (a node slow to stop
    # on a busy host: SIGTERM after 5 s, SIGKILL 5 s later); Proc.stop() would send its
    # own SIGTERM after 5 s and SIGKILL the launcher mid-way (s13L4: exit -9).
    launch.popen.send_signal(signal.SIGINT)
    assert launch.popen.wait(30) == 0, launch.output[-3000:]
