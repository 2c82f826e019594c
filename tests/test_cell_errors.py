"""A student's own error in a cell, in a real kernel: their frames and one `Try:` line.

Each cell below raises as a student's cell does (a misspelt name, a wrong call into rclpy,
a typo inside a node class, a kit error); the error output must keep every frame of the
student's code, show none of the kit's or rclpy's, end with a line that says how to fix it,
and still fail the cell (nbval, nbgrader and autograde count it). An instructor's switch
(ROBOT_LAB_FULL_TRACEBACKS=1) brings back the full traceback.
"""

from __future__ import annotations

import re

import pytest
from course_run import Course, error
from nbformat import v4

SETUP = ("import robot_lab\nfrom robot_lab.grading import check, setup\n"
         "lesson = setup('02_write_nodes')")

NAME_ERROR = "def wiring(topic):\n    return topic\n\nwirng('/robot/status')"
RCLPY_CALL = ("from std_msgs.msg import Float32\nsession = robot_lab.session()\n"
              "session.node.create_publisher(Float32, 'sensor temperature', 10)")
NODE_TYPO = ("from rclpy.node import Node\n\n\n"
             "class SensorNode(Node):\n"
             "    def __init__(self):\n"
             "        super().__init__('sensor_typo')\n"
             "        self.declare_parameter('sensor_rate', 10)\n"
             "        self.rate = self.get_parameter('sensor_rte').value\n\n\n"
             "node = SensorNode()")
KIT_ERROR = "robot_lab.param_get('/no_such_node', 'sensor_rate')"
CHECK_FAILS = "check.eventually(lambda: False, 'a thing', timeout=0, hint='do it')"
FULL = "import os\nos.environ['ROBOT_LAB_FULL_TRACEBACKS'] = '1'"


def _shown(cell: object) -> str:
    found = error(cell)  # type: ignore[arg-type]
    assert found is not None, 'the cell did not fail'
    return re.sub(r'\x1b\[[0-9;]*m', '', '\n'.join(found.traceback))


def _no_library_frames(shown: str) -> None:
    assert not re.search(r'site-packages|robot_lab/\w+|rclpy/node\.py|File "/', shown), shown


@pytest.fixture(scope='module')
def ran(tmp_path_factory: pytest.TempPathFactory, ros_domain: int) -> list[str]:
    course = Course(tmp_path_factory.mktemp('errors') / 'ws', ros_domain)
    sources = [SETUP, NAME_ERROR, RCLPY_CALL, NODE_TYPO, KIT_ERROR, CHECK_FAILS, FULL,
               RCLPY_CALL]
    left = course.run('02_write_nodes', [v4.new_code_cell(s) for s in sources])
    assert left['children'] == [], left
    assert error(course.cells[0]) is None
    return [_shown(cell) for cell in course.cells[1:len(sources)] if error(cell) is not None]


def test_a_misspelt_name_names_the_one_meant(ran: list[str]) -> None:
    shown = ran[0]
    assert "wirng('/robot/status')" in shown and 'NameError' in shown, shown
    assert re.search(r'^Try: did you mean `wiring`\?', shown, re.M), shown
    _no_library_frames(shown)


def test_a_wrong_call_into_rclpy_stops_at_the_students_line(ran: list[str]) -> None:
    shown = ran[1]
    assert "create_publisher(Float32, 'sensor temperature', 10)" in shown, shown
    assert 'InvalidTopicNameException' in shown, shown
    assert re.search(r'^Try: the call at your line 3 gives rclpy\.node\.create_publisher\(\)',
                     shown, re.M), shown
    _no_library_frames(shown)


def test_a_typo_in_a_node_class_keeps_every_frame_of_the_student(ran: list[str]) -> None:
    shown = ran[2]
    # both of the student's frames: the line that made the node, the line in __init__
    assert 'node = SensorNode()' in shown, shown
    assert "self.rate = self.get_parameter('sensor_rte').value" in shown, shown
    assert 'in SensorNode.__init__' in shown, shown
    assert 'ParameterNotDeclaredException' in shown, shown
    assert re.search(r'^Try: the call at your line 8 gives rclpy\.node\.get_parameter\(\)',
                     shown, re.M), shown
    _no_library_frames(shown)


def test_a_kit_error_says_its_fix_once(ran: list[str]) -> None:
    shown = ran[3]
    assert "Node not found: '/no_such_node' — fix: check the name" in shown, shown
    assert 'Try:' not in shown, shown
    _no_library_frames(shown)


def test_a_failed_check_still_renders_as_two_lines(ran: list[str]) -> None:
    lines = [ln for ln in ran[4].splitlines() if ln.strip()]
    assert lines == ['✗ expected a thing; observed it is not so', 'Try: do it'], lines


def test_the_instructors_switch_shows_every_frame(ran: list[str]) -> None:
    shown = ran[5]
    assert 'rclpy/node.py' in shown and 'Try:' not in shown, shown

