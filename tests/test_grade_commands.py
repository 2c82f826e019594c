"""`controller_commands` for commands of any type (issue 51): every field of the command is
read (bools, integers, strings, arrays, nested messages), a command follows its input when
any field changes with it, the feedback names the fields that changed, and the advice fits
what the controller publishes. Real nodes: a light sensor and controllers publishing an
Int32 level, a String state, a nested diagnostic status and a stuck Bool, driven by the
grader's own perturbation; the lamp (a Bool with hysteresis) is graded whole in
tests/test_grade_faults.py."""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from conftest import Proc

from robot_lab.env import ros_environment
from robot_lab.grading.package import perturb
from robot_lab.grading.package.checks.controller_commands import (
    command_hint,
    controller_commands,
)
from robot_lab.grading.package.perturb import Response, _follows, command_fields
from robot_lab.grading.package.roles import Observation, Roles, TopicSeen, observe
from robot_lab.grading.package.rubric import Rubric, RubricCheck
from robot_lab.grading.package.state import JobState

CHECK = RubricCheck('controller_commands', 'A controller', 2.0)


def test_every_field_is_read_whatever_its_type() -> None:
    status = {'level': [1], 'name': 'lamp', 'message': 'dusk',
              'values': [{'key': 'lamp', 'value': 'on'}, {'key': 'lux', 'value': '120'}]}
    assert dict(command_fields(status)) == {
        'level[0]': 1, 'name': 'lamp', 'message': 'dusk', 'values[0].key': 'lamp',
        'values[0].value': 'on', 'values[1].key': 'lux', 'values[1].value': '120'}
    stamped = {'header': {'stamp': {'sec': 5, 'nanosec': 7}, 'frame_id': 'base'},
               'data': True, 'flags': [False, True]}
    assert dict(command_fields(stamped)) == {'data': True, 'flags[0]': False,
                                             'flags[1]': True}


def test_a_bool_or_a_word_that_flips_with_the_input_follows_it() -> None:
    assert _follows({'data': True}, {'data': False}, {'data': True})
    assert not _follows({'data': True}, {'data': True}, {'data': True})
    assert not _follows({'data': True}, {'data': False}, {'data': False})  # a latch
    assert _follows({'state': 'DARK'}, {'state': 'BRIGHT'}, {'state': 'DARK'})
    assert _follows({'level': 0.0}, {'level': 2.0}, {'level': 0.0})


def test_the_table_shows_a_bool_and_names_the_fields_that_changed() -> None:
    levels: list[tuple[float, perturb.Sample, int]] = [
        (50.0, {'data': True, 'id': 3.0}, 5), (600.0, {'data': False, 'id': 3.0}, 5),
        (50.0, {'data': True, 'id': 3.0}, 5)]
    response = Response(True, levels=levels)
    assert response.table().splitlines()[1] == '- input 600 → 5 command(s): data = False, id = 3'
    assert response.changed() == ['data']


@pytest.mark.parametrize(('type_name', 'last', 'says', 'never'), [
    ('geometry_msgs/msg/Twist', {'linear': {'x': 0.5, 'y': 0.0, 'z': 0.0},
                                 'angular': {'x': 0.0, 'y': 0.0, 'z': 0.0}},
     'speed = gain', 'threshold'),
    ('std_msgs/msg/Bool', {'data': True}, 'msg.data = reading < threshold', 'speed'),
    ('std_msgs/msg/Int32', {'data': 2}, 'choose the level', 'speed'),
    ('std_msgs/msg/String', {'data': 'ON'}, 'choose the state', 'speed'),
    ('lamp_interfaces/msg/LampCommand', {'on': True, 'brightness': 0.4, 'mode': 'auto'},
     'your `LampCommand` message (`on`, `brightness`, `mode`)', 'speed'),
])
def test_the_hint_fits_the_command_type(type_name: str, last: dict[str, object], says: str,
                                        never: str) -> None:
    hint = command_hint(type_name, last)
    assert says in hint and never not in hint


class _SwitchOnly:
    """Stands in for the grader's wires to a lamp controller that publishes only when it
    switches (on below 200 lx, off above 250 lx), answering at once."""

    def __init__(self, sess: object, bridge: object, sensor: TopicSeen, command: TopicSeen,
                 on_command: Callable[[dict[str, Any]], None]) -> None:
        self.on_command, self.on = on_command, True  # on already: the first low is silent

    def make(self, data: dict[str, Any]) -> dict[str, Any]:
        return data

    def publish(self, message: dict[str, Any]) -> None:
        lux = message['illuminance']
        on = True if lux < 200 else False if lux > 250 else self.on
        if on != self.on:
            self.on = on
            self.on_command({'data': on})

    def matched(self) -> int:
        return 1

    def close(self) -> None:
        pass


def test_a_lamp_told_only_when_it_switches_follows(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(perturb, '_Wires', _SwitchOnly)
    monkeypatch.setattr(perturb, '_PATIENCE', 0.2)  # its answers come at once
    light = TopicSeen('/light', ['sensor_msgs/msg/Illuminance'])
    light.values.extend([{'illuminance': 120.0}, {'illuminance': 420.0}])
    obs = Observation(topics={'/light': light, '/lamp': TopicSeen('/lamp',
                                                                  ['std_msgs/msg/Bool'])})
    roles = Roles(sensor='/s', sensor_topic='/light', controller='/c', command_topic='/lamp')
    response = perturb.drive_controller(
        None, obs, roles, lambda: ((lambda: None), 'paused'))  # type: ignore[arg-type]
    assert response.follows and response.changed() == ['data'], response.table()
    assert 'the last one stands' in response.table()


# --- Real nodes: a sensor and controllers of several command types ---------------------

SENSOR = """
import math, rclpy
from rclpy.node import Node
from sensor_msgs.msg import Illuminance

class LightSensor(Node):
    def __init__(self):
        super().__init__('light_sensor')
        self.pub = self.create_publisher(Illuminance, 'ambient_light', 10)
        self.t = 0.0
        self.create_timer(0.1, self.measure)

    def measure(self):
        self.t += 0.1
        self.pub.publish(Illuminance(illuminance=300.0 + 280.0 * math.sin(3.0 * self.t)))

rclpy.init()
rclpy.spin(LightSensor())
"""

CONTROLLERS = '''
import rclpy
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import Illuminance
from std_msgs.msg import Bool, Int32, String

class Controller(Node):
    """One light-driven controller; `command(lux)` makes its message."""
    def __init__(self, name, kind, topic, command):
        super().__init__(name)
        self.command = command
        self.pub = self.create_publisher(kind, topic, 10)
        self.create_subscription(Illuminance, 'ambient_light', self.on_light, 10)

    def on_light(self, msg):
        self.pub.publish(self.command(msg.illuminance))

def level(lux):
    return Int32(data=0 if lux < 150 else 1 if lux < 400 else 2)

def state(lux):
    return String(data='DARK' if lux < 200 else 'BRIGHT')

def status(lux):
    on = KeyValue(key='lamp', value='on' if lux < 200 else 'off')
    return DiagnosticStatus(level=b'\\x00', name='lamp', message='lamp status', values=[on])

rclpy.init()
executor = SingleThreadedExecutor()
for node in (Controller('level_ctl', Int32, 'fan_level', level),
             Controller('state_ctl', String, 'lamp_state', state),
             Controller('status_ctl', DiagnosticStatus, 'lamp_status', status),
             Controller('stuck_ctl', Bool, 'lamp_stuck', lambda lux: Bool(data=True))):
    executor.add_node(node)
print('controllers up', flush=True)
executor.spin()
'''


@pytest.fixture(scope='module')
def system(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Observation, int]]:
    """The sensor and the controllers running, watched once as the grader watches."""
    from robot_lab.rclpy_session import session

    folder = tmp_path_factory.mktemp('nodes')
    (folder / 'sensor.py').write_text(SENSOR)
    (folder / 'controllers.py').write_text(CONTROLLERS)
    env = ros_environment()
    sensor = Proc([sys.executable, str(folder / 'sensor.py')], env=env)
    controllers = Proc([sys.executable, str(folder / 'controllers.py')], env=env)
    try:
        obs = observe(session(), 5, 30.0, 1.0, alive=lambda: True)
        yield obs, sensor.popen.pid
    finally:
        sensor.stop()
        controllers.stop()


def _pause(pid: int) -> Callable[[], tuple[Callable[[], None], str]]:
    def pause() -> tuple[Callable[[], None], str]:
        os.kill(pid, signal.SIGSTOP)
        return (lambda: os.kill(pid, signal.SIGCONT)), "the sensor's process was paused"
    return pause


def _judged(obs: Observation, controller: str, topic: str, sensor_pid: int) -> tuple[
        Response, str, bool]:
    """Drive one controller as the grader does; its response, feedback and result."""
    from robot_lab.rclpy_session import session

    roles = Roles(sensor='/light_sensor', sensor_topic='/ambient_light',
                  controller=controller, command_topic=topic)
    assert obs.topics[topic].count > 0, f'{topic} was not heard: {list(obs.topics)}'
    response = perturb.drive_controller(session(), obs, roles, _pause(sensor_pid))
    state = JobState(Rubric('lab', '', [CHECK]))
    state.live.obs, state.live.roles, state.live.response = obs, roles, response
    verdict = controller_commands(state, CHECK)
    return response, verdict.text(), verdict.fraction >= 1


@pytest.mark.timeout(120)
@pytest.mark.parametrize(('controller', 'topic', 'field'), [
    ('/level_ctl', '/fan_level', 'data'),
    ('/state_ctl', '/lamp_state', 'data'),
    ('/status_ctl', '/lamp_status', 'values[0].value'),
])
def test_commands_of_any_type_follow_the_input(system: tuple[Observation, int],
                                               controller: str, topic: str,
                                               field: str) -> None:
    obs, pid = system
    response, text, passed = _judged(obs, controller, topic, pid)
    assert response.follows and passed, text
    assert field in response.changed(), text
    assert 'its commands follow the input (fields that changed with the input:' in text
    assert f'`{field}`' in text.rsplit('fields that changed', 1)[1], text


@pytest.mark.timeout(120)
def test_a_stuck_bool_does_not_follow_and_gets_bool_advice(
        system: tuple[Observation, int], monkeypatch: pytest.MonkeyPatch) -> None:
    # A constant controller never answers a level: each is read after the patience, which
    # needs no length here (the verdict comes from the commands staying the same).
    monkeypatch.setattr(perturb, '_PATIENCE', 0.3)
    obs, pid = system
    response, text, passed = _judged(obs, '/stuck_ctl', '/lamp_stuck', pid)
    assert response.tested and not response.follows and not passed, text
    assert 'data = True' in text and 'no field of the command changed' in text
    assert 'msg.data = reading < threshold' in text and 'speed' not in text



@pytest.mark.timeout(120)
def test_types_the_grader_does_not_load_are_read_and_written_by_the_helper(
        system: tuple[Observation, int], monkeypatch: pytest.MonkeyPatch) -> None:
    """A student's own interfaces are never imported by the grader: its helper process
    (robot_lab.grading.package.bridge) reads the commands and publishes the readings.
    Here the grader's process refuses the sensor's and the status controller's types, as
    it does a student's interface package's."""
    from robot_lab import messages
    from robot_lab.errors import GraphError
    from robot_lab.grading.package.bridge import Bridge
    from robot_lab.rclpy_session import session

    kit_type = messages.message_class
    refused = ('sensor_msgs/msg/Illuminance', 'diagnostic_msgs/msg/DiagnosticStatus')

    def grader_types(name: str) -> object:
        if name in refused:
            raise GraphError(f'{name}: not loaded in the grader')
        return kit_type(name)

    monkeypatch.setattr(messages, 'message_class', grader_types)
    _, pid = system
    bridge = Bridge()
    try:
        obs = observe(session(), 5, 30.0, 1.0, alive=lambda: True, bridge=bridge)
        assert obs.topics['/ambient_light'].count > 0 and obs.topics['/lamp_status'].count > 0
        roles = Roles(sensor='/light_sensor', sensor_topic='/ambient_light',
                      controller='/status_ctl', command_topic='/lamp_status')
        response = perturb.drive_controller(session(), obs, roles, _pause(pid), bridge)
    finally:
        bridge.close()
    assert response.follows, response.table()
    assert response.changed() == ['values[0].value'], response.table()
    assert not bridge.errors
