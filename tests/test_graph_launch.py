"""Issue 4's acceptance, with the real launcher: `robot-lab launch robot_lab robot.launch.xml`
and the inspect verbs typed right after it, as a student would."""

from __future__ import annotations

from conftest import run_cli
from rosutil import check_ten_hertz, last_hz_window


def test_inspect_a_launched_system(start) -> None:  # type: ignore[no-untyped-def]
    launch = start('robot-lab', 'launch', 'robot_lab', 'robot.launch.xml')
    for started in (r'Sensor node started', r'Controller node started',
                    r'Robot node started: my_robot'):
        launch.wait_for(started, timeout=30)
    # at once, no waiting of our own: the verb must let discovery settle by itself
    listed = run_cli('node', 'list')
    assert listed.stdout == '/controller\n/robot\n/sensor\n', listed.stderr
    assert run_cli('param', 'get', '/sensor', 'sensor_rate').stdout == 'Integer value is: 10\n'
    refused = run_cli('param', 'set', '/sensor', 'noise_level', 'abc')
    assert refused.stderr.startswith('Setting parameter failed: ')
    hz = run_cli('topic', 'hz', '/sensor/temperature', '--window', '20', '--duration', '4')
    check_ten_hertz(*last_hz_window(hz.stdout)[:3])  # still 10 Hz after the refusal
    assert launch.popen.poll() is None
