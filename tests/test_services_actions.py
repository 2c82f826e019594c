"""Services, actions and interfaces: `ros2 service|action|interface` verbs and the notebook
API, against the kit's real example servers (switch_node, fibonacci_node).

The expected texts are ros2cli's (Jazzy): ros2service/verb/call.py, ros2action/verb/
send_goal.py, ros2interface/verb/*.py.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Iterator

import pytest
from conftest import BIN, Proc, cli_ok, cli_ok_all, run_cli

import robot_lab
from robot_lab.errors import GraphError


@pytest.fixture(scope='module')
def servers(ros_domain: int) -> Iterator[dict[str, Proc]]:
    """/switch and /fibonacci_action_server (0.05 s per Fibonacci step) for the module."""
    procs = {
        'switch': Proc([str(BIN / 'robot-lab'), 'run', 'robot_lab', 'switch_node']),
        'fibonacci': Proc([str(BIN / 'robot-lab'), 'run', 'robot_lab', 'fibonacci_node',
                           '--ros-args', '-p', 'step_period:=0.05']),
    }
    try:
        procs['switch'].wait_for('Switch node started', timeout=20)
        procs['fibonacci'].wait_for('Fibonacci action server started', timeout=20)
        robot_lab.wait_for_nodes(['/switch', '/fibonacci_action_server'], timeout=10)
        yield procs
    finally:
        for proc in procs.values():
            proc.stop()


def test_service_list_type_find_info(servers: dict[str, Proc]) -> None:
    listed, kind, found, info = cli_ok_all(
        ('service', 'list', '-t'), ('service', 'type', '/enable'),
        ('service', 'find', 'std_srvs/srv/Trigger'), ('service', 'info', '/enable'))
    assert '/enable [std_srvs/srv/SetBool]' in listed.splitlines()
    assert '/get_state [std_srvs/srv/Trigger]' in listed.splitlines()
    assert '/_action/' not in listed  # an action's services are hidden, as in ros2cli
    assert kind == 'std_srvs/srv/SetBool\n'
    assert found == '/get_state\n'
    assert info == 'Type: std_srvs/srv/SetBool\nClients count: 0\nServices count: 1\n'
    assert robot_lab.service_type('/nope', timeout=0.2) == []


def test_service_call_prints_request_and_response(servers: dict[str, Proc]) -> None:
    out = cli_ok('service', 'call', '/enable', 'std_srvs/srv/SetBool', '{data: true}')
    # 'waiting for service...' only if the cold process had not yet discovered the server
    assert out.removeprefix('waiting for service to become available...\n') == (
        'requester: making request: std_srvs.srv.SetBool_Request(data=True)\n\n'
        'response:\n'
        "std_srvs.srv.SetBool_Response(success=True, message='enabled')\n\n"
    )
    servers['switch'].wait_for(r'\[switch\]: Robot enabled')
    repeated = cli_ok('service', 'call', '/get_state', 'std_srvs/srv/Trigger',
                      '-r', '20', '-n', '2')
    assert repeated.count("std_srvs.srv.Trigger_Response(success=True, message='enabled')") == 2


def test_service_call_errors_are_one_line(servers: dict[str, Proc]) -> None:
    bad_type = run_cli('service', 'call', '/enable', 'std_srvs/srv/Nope')
    assert bad_type.returncode == 1
    assert "The passed service type 'std_srvs/srv/Nope' is invalid" in bad_type.stderr
    bad_field = run_cli('service', 'call', '/enable', 'std_srvs/srv/SetBool', '{dta: 1}')
    assert bad_field.returncode == 1 and 'Traceback' not in bad_field.stderr
    assert "'dta' is not a field of std_srvs/srv/SetBool_Request" in bad_field.stderr


def test_call_service_from_a_notebook(servers: dict[str, Proc]) -> None:
    response = robot_lab.call_service('/enable', 'std_srvs/srv/SetBool', {'data': False})
    assert (response.success, response.message) == (True, 'disabled')
    state = robot_lab.call_service('get_state', 'std_srvs/srv/Trigger')
    assert (state.success, state.message) == (False, 'disabled')
    info = robot_lab.service_info('/get_state')
    assert (info.types, info.servers, info.clients) == (['std_srvs/srv/Trigger'], 1, 1)
    with pytest.raises(GraphError, match=r"service '/absent' not available within 0\.3 s"):
        robot_lab.call_service('/absent', 'std_srvs/srv/Trigger', timeout=0.3)


def test_action_list_type_info(servers: dict[str, Proc]) -> None:
    listed, kind, info, node = cli_ok_all(
        ('action', 'list', '-t'), ('action', 'type', '/fibonacci'),
        ('action', 'info', '/fibonacci', '-t'), ('node', 'info', '/fibonacci_action_server'))
    assert listed == '/fibonacci [test_msgs/action/Fibonacci]\n'
    assert kind == 'test_msgs/action/Fibonacci\n'
    assert info == (
        'Action: /fibonacci\n'
        'Action clients: 0\n'
        'Action servers: 1\n'
        '    /fibonacci_action_server [test_msgs/action/Fibonacci]\n'
    )
    assert node.endswith('  Action Servers:\n    /fibonacci: test_msgs/action/Fibonacci\n'
                         '  Action Clients:\n\n')
    assert '/_action/' not in node  # the action's topics and services are hidden ones


def test_action_send_goal_with_feedback(servers: dict[str, Proc]) -> None:
    out = cli_ok('action', 'send_goal', '--feedback', '/fibonacci', 'test_msgs/action/Fibonacci',
             '{order: 3}')
    goal_id = re.search(r'Goal accepted with ID: ([0-9a-f]{32})\n', out)
    assert goal_id is not None, out
    assert out.replace(goal_id.group(1), 'ID') == (
        'Waiting for an action server to become available...\n'
        'Sending goal:\n     order: 3\n\n'
        'Goal accepted with ID: ID\n\n'
        'Feedback:\n    sequence:\n- 0\n- 1\n- 1\n\n'
        'Feedback:\n    sequence:\n- 0\n- 1\n- 1\n- 2\n\n'
        'Result:\n    sequence:\n- 0\n- 1\n- 1\n- 2\n\n'
        'Goal finished with status: SUCCEEDED\n'
    )


def test_send_goal_from_a_notebook_feedback_and_cancel(servers: dict[str, Proc]) -> None:
    seen: list[list[int]] = []
    goal = robot_lab.send_goal('/fibonacci', 'test_msgs/action/Fibonacci', {'order': 5},
                               feedback=lambda f: seen.append(list(f.sequence)))
    assert goal.status == 'SUCCEEDED'
    assert list(goal.result.sequence) == [0, 1, 1, 2, 3, 5]
    assert seen == [[0, 1, 1], [0, 1, 1, 2], [0, 1, 1, 2, 3], [0, 1, 1, 2, 3, 5]]
    assert [list(f.sequence) for f in goal.feedback] == seen

    # A long goal, watched and cancelled midway (the server checks between steps).
    two = threading.Event()
    long_goal = robot_lab.send_goal(
        'fibonacci', 'test_msgs/action/Fibonacci', '{order: 40}', wait=False,
        feedback=lambda f: two.set() if len(f.sequence) >= 4 else None)
    assert long_goal.accepted and not long_goal.done
    assert two.wait(10)
    assert long_goal.cancel()
    long_goal.wait(10)
    assert long_goal.status == 'CANCELED'
    assert 4 <= len(long_goal.result.sequence) < 41

    rejected = robot_lab.send_goal('/fibonacci', 'test_msgs/action/Fibonacci', {'order': 99})
    assert (rejected.accepted, rejected.status, rejected.done) == (False, 'REJECTED', True)


def test_interface_verbs() -> None:
    assert cli_ok('interface', 'package', 'std_srvs') == (
        'std_srvs/srv/Empty\nstd_srvs/srv/SetBool\nstd_srvs/srv/Trigger\n')
    assert 'test_msgs\n' in cli_ok('interface', 'packages', '-a')
    listed = cli_ok('interface', 'list', '-a').splitlines()
    assert listed[0] == 'Actions:' and '    test_msgs/action/Fibonacci' in listed
    assert cli_ok('interface', 'proto', 'test_msgs/action/Fibonacci') == '"order: 0\n"\n'
    assert cli_ok('interface', 'proto', 'geometry_msgs/msg/Vector3', '--no-quotes') == (
        'x: 0.0\ny: 0.0\nz: 0.0\n\n')
    missing = run_cli('interface', 'package', 'nope')
    assert missing.returncode == 1 and "Unknown package 'nope'" in missing.stderr
