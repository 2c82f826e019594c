"""A sensor that simulates the plant closes the loop (issue 51): it reads the commands and
publishes the measurement they lead to. The assignment asks only that "a sensor node
publishes simulated data", so such a design is a sensor, and the controller and actuator
downstream of it are graded as in an open loop. A node whose input comes from outside its
loop (a relay) or that never publishes stays no sensor. The roles are checked on graphs
written out by hand; one closed-loop student is graded for real."""

from __future__ import annotations

import csv
import shutil
from collections.abc import Mapping
from pathlib import Path

import pytest
from conftest import REPO, run_cli

from robot_lab.grading.package.roles import NodeSeen, Observation, TopicSeen, infer_roles

pytestmark = pytest.mark.timeout(600)


def _graph(nodes: dict[str, tuple[list[str], list[str]]],
           rates: Mapping[str, float]) -> Observation:
    """An observation of `nodes` (name: (publishes, subscribes)); each topic of `rates`
    delivered at that rate for 3 s (a topic not in it: nothing heard)."""
    obs = Observation(duration=3.0)
    for name, (pubs, subs) in nodes.items():
        obs.nodes[name] = NodeSeen(name, sorted(pubs), sorted(subs))
    topics = {t for pubs, subs in nodes.values() for t in pubs + subs}
    for topic in sorted(topics):
        seen = TopicSeen(topic, ['std_msgs/msg/Float64'],
                         publishers=sorted(n for n, (p, _) in nodes.items() if topic in p),
                         subscribers=sorted(n for n, (_, s) in nodes.items() if topic in s))
        if (rate := rates.get(topic, 0.0)) > 0:
            seen.count, seen.first, seen.last = int(3 * rate) + 1, 0.0, 3.0
        obs.topics[topic] = seen
    return obs


# ivan's thermostat: the thermometer simulates the room from the heater's switch.
LOOP = {'/thermometer': (['/room/temperature'], ['/heater/on']),
        '/thermostat': (['/heater/on'], ['/room/temperature']),
        '/heater': ([], ['/heater/on'])}


def test_a_sensor_that_reads_its_loops_commands_is_the_sensor() -> None:
    roles = infer_roles(_graph(LOOP, {'/room/temperature': 4, '/heater/on': 4}), 0.5)
    assert (roles.sensor, roles.sensor_topic) == ('/thermometer', '/room/temperature')
    assert (roles.controller, roles.command_topic) == ('/thermostat', '/heater/on')
    assert roles.actuator == '/heater'


def test_a_sensor_that_reads_what_the_actuator_reports_is_the_sensor() -> None:
    nodes = {'/odometer': (['/speed'], ['/wheel/state']),
             '/cruise': (['/throttle'], ['/speed']),
             '/wheel': (['/wheel/state'], ['/throttle'])}
    obs = _graph(nodes, {'/speed': 10, '/throttle': 10, '/wheel/state': 10})
    obs.nodes['/wheel'].log_count = 30  # the actuator logs each command
    roles = infer_roles(obs, 0.5)
    assert (roles.sensor, roles.controller, roles.actuator) == ('/odometer', '/cruise',
                                                                 '/wheel')


def test_an_open_loop_sensor_still_comes_first() -> None:
    nodes = {'/sensor': (['/distance'], []),
             '/controller': (['/cmd_vel'], ['/distance']),
             '/robot': ([], ['/cmd_vel'])}
    roles = infer_roles(_graph(nodes, {'/distance': 2, '/cmd_vel': 2}), 0.5)
    assert (roles.sensor, roles.controller, roles.actuator) == ('/sensor', '/controller',
                                                                 '/robot')


def test_a_heartbeat_nobody_controls_from_does_not_hide_the_loop() -> None:
    nodes = dict(LOOP, **{'/heartbeat': (['/alive'], [])})
    rates = {'/room/temperature': 4, '/heater/on': 4, '/alive': 10}
    assert infer_roles(_graph(nodes, rates), 0.5).sensor == '/thermometer'


def test_a_sensor_that_never_publishes_is_no_sensor() -> None:
    roles = infer_roles(_graph(LOOP, {}), 0.5)
    assert (roles.sensor, roles.controller, roles.actuator) == (None, None, None)


def test_a_relay_of_input_from_outside_the_loop_is_no_sensor() -> None:
    nodes = dict(LOOP)
    nodes['/thermometer'] = (['/room/temperature'], ['/heater/on', '/weather'])
    nodes['/weather_feed'] = (['/weather'], [])
    rates = {'/room/temperature': 4, '/heater/on': 4, '/weather': 4}
    roles = infer_roles(_graph(nodes, rates), 0.5)
    assert (roles.sensor, roles.controller) == ('/weather_feed', '/thermometer')


def test_a_closed_loop_student_gets_full_marks(tmp_path: Path) -> None:
    root = tmp_path / 'class'
    shutil.copytree(REPO / 'tests' / 'data' / 'class_independent' / 'ivan', root / 'ivan')
    out = tmp_path / 'out'
    done = run_cli('grade', str(root), '--lab', 'ch6-lab1', '-o', str(out), timeout=500)
    assert done.returncode == 0, done.stdout + done.stderr
    with (out / 'grades.csv').open() as f:
        ivan = next(csv.DictReader(f))
    assert f"{ivan['score']}/{ivan['max_score']}" == '13/13', ivan
    feedback = (out / 'feedback' / 'ivan.md').read_text()
    assert 'sensor `/thermometer` publishes `/room/temperature`' in feedback
    # Paused, the sensor does not answer the grader's drive with readings of its own.
    assert "the sensor's process was paused" in feedback
