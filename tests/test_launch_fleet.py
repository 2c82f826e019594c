"""launch/robot_fleet.launch.xml: ten robots that do not hear each other (issue 15.6).

Starting its 30 nodes takes far longer than a test may on a shared 2-core machine, so the
run is bench/bench_load.py's; this checks what the launcher would start, as evaluated.
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

import yaml

from robot_lab.launch.resolve import describe_launch


def test_fleet_is_ten_namespaced_robots_with_their_own_topics() -> None:
    plan = describe_launch('robot_lab', 'robot_fleet.launch.xml', {})
    specs = plan.processes()
    try:
        assert len(specs) == 30
        assert sorted(spec.node_name or '' for spec in specs) == sorted(
            f'/robot{n}/{node}' for n in range(1, 11) for node in ('sensor', 'controller', 'robot'))
        for spec in specs:
            namespace = re.fullmatch(r'(/robot\d+)/\w+', spec.node_name or '')
            assert namespace, spec.node_name
            args = spec.cmd[spec.cmd.index('--ros-args'):]
            assert f'__ns:={namespace.group(1)}' in args
            # absolute topics remapped into the robot's namespace: no cross-talk
            for topic in ('/sensor/temperature', '/robot/status', '/cmd_vel'):
                assert f'{topic}:={topic[1:]}' in args, (spec.node_name, topic)
            if spec.executable == 'robot_node':
                number = int(namespace.group(1).removeprefix('/robot'))
                params = yaml.safe_load(Path(spec.param_files[-1]).read_text())
                assert params[spec.node_name]['ros__parameters'] == {
                    'robot_name': f'robot_{number:02d}'}
            else:
                assert Path(spec.param_files[0]).name == 'robot_params.yaml'
    finally:
        for spec in specs:
            for path in spec.param_files:
                if Path(path).name.startswith('launch_params_'):
                    with contextlib.suppress(OSError):
                        Path(path).unlink()
