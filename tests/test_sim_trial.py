"""A controller driven against a world and judged by the simulator's ground truth.

Real processes: the trial's simulator and bridge, and controllers as nodes of this
process (as a notebook's check cell runs the student's). One simulator serves the
bridged cases (a run resets the world), in lockstep (each scan waits for the controller's
answer: deterministic, and as fast as the controller answers); the unbridged case has its
own, free-running at 10x real time.
The judgement's words are tested on samples alone.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from robot_lab.sim.trial import Trial, TrialResult, judge_stop
from robot_lab.sim.trial_result import bridge_command

SCAN_HINT = bridge_command('scan', 'scan')


def _stopper(name: str, stop_at: float, sim_time: bool) -> Any:
    """The Chapter 6 controller against /scan: slow down towards `stop_at` m ahead (of the
    lidar), then stop; `stop_at` < 0 never stops."""
    from geometry_msgs.msg import Twist
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import LaserScan

    from robot_lab.rclpy_session import session

    class Stopper(Node):
        def __init__(self) -> None:
            super().__init__(name, context=session().context,
                             parameter_overrides=[Parameter('use_sim_time', value=sim_time)])
            self.pub = self.create_publisher(Twist, '/cmd_vel', 10)
            self.create_subscription(LaserScan, '/scan', self.on_scan, 10)

        def on_scan(self, msg: Any) -> None:
            ahead = msg.ranges[len(msg.ranges) // 2]  # the beam at angle 0
            cmd = Twist()
            if ahead > stop_at:
                cmd.linear.x = min(0.4, 1.5 * (ahead - stop_at))
            self.pub.publish(cmd)

    return session().add_node(Stopper())


def _run(trial: Trial, name: str, stop_at: float, sim_time: bool, **options: Any
         ) -> TrialResult:
    from robot_lab.rclpy_session import session

    node = _stopper(name, stop_at, sim_time)
    try:
        return trial.run(**options)
    finally:
        session().remove_node(node)
        node.destroy_node()


def test_without_a_bridge_the_result_says_what_to_bridge() -> None:
    # First in the module: the shared trial's bridge, once up, publishes /scan domain-wide.
    with Trial('wall', bridge=False, speed=10.0) as trial:
        result = _run(trial, 'unbridged', 0.5, True, sim_seconds=0.5, controller_timeout=2.0)
        children = list(trial.children)
    assert all(child.proc.poll() is not None for child in children)  # nothing outlives it
    assert result.scan_publishers == () and not result.received_cmd_vel
    assert not result.moved and result.sim_seconds == pytest.approx(0.5, abs=0.02)
    passed, line = judge_stop(result, 0.3, 0.05)
    assert not passed
    assert line == ('never received /scan: nothing publishes /scan; the simulator publishes '
                    f'gz topic /scan; bridge it with: {SCAN_HINT}')
    assert SCAN_HINT.endswith('/scan@sensor_msgs/msg/LaserScan[gz.msgs.LaserScan')


@pytest.fixture(scope='module')
def trial() -> Iterator[Trial]:
    # the wall's face 1 m ahead of the lidar; each scan waits for its answer
    with Trial('wall', speed=20.0, lockstep=True) as running:
        yield running
    assert all(child.proc.poll() is not None for child in running.children)


def test_a_controller_that_stops_in_time_is_measured_from_the_robots_front(
        trial: Trial) -> None:
    result = _run(trial, 'good_stopper', 0.5, True, sim_seconds=8.0)
    # the lidar sits at the chassis' centre, 0.2 m behind its front: 0.5 - 0.2
    assert result.start_distance == pytest.approx(0.8, abs=0.005)
    assert result.final_distance == pytest.approx(0.3, abs=0.05)
    assert not result.collision and result.stopped and result.ended == 'rest'
    assert result.received_cmd_vel and result.scan_publishers == ('/ros_gz_bridge',)
    assert '/good_stopper' in result.scan_subscribers
    assert dict(result.use_sim_time) == {'/good_stopper': True}
    passed, line = judge_stop(result, 0.3, 0.05, obstacle='the wall')
    assert passed, line
    assert line.startswith('stopped 0.') and '(target 0.30 ± 0.05)' in line


def test_in_lockstep_the_same_controller_drives_the_same_trajectory(trial: Trial) -> None:
    first = _run(trial, 'again_1', 0.5, True, sim_seconds=2.0, until_rest=0.0)
    second = _run(trial, 'again_2', 0.5, True, sim_seconds=2.0, until_rest=0.0)
    assert len(first.samples) == len(second.samples) == 200
    assert first.samples == second.samples  # the world reset between: the same ground truth
    assert first.commands == second.commands  # one answer per scan (10 Hz): the last
    assert 19 <= first.commands <= 20         # scan's may come after the last sample


def test_a_controller_that_never_stops_hits_the_wall(trial: Trial) -> None:
    result = _run(trial, 'reckless', -1.0, False, sim_seconds=8.0)
    assert result.collision and result.ended == 'collision'
    assert result.collision_speed == pytest.approx(0.4, abs=0.05)
    assert result.collision_time is not None and 1.5 < result.collision_time < 3.5
    assert result.min_distance <= 0.001
    passed, line = judge_stop(result, 0.3, 0.05, obstacle='the wall')
    assert not passed
    assert line.startswith('hit the wall at 0.4')
    assert '/reckless runs without use_sim_time' in line


def test_a_world_that_cannot_load_stops_the_trial_with_its_reason() -> None:
    from robot_lab.sim.xml_tree import SimulationError

    trial = Trial('no_such_world.sdf')
    with pytest.raises(SimulationError, match=r'no_such_world\.sdf'):
        trial.start()
    assert all(child.proc.poll() is not None for child in trial.children)


# -- the words, from samples alone -----------------------------------------------------------
def _samples(gaps: list[float], step: float = 0.01, touching_below: float = 0.0
             ) -> list[dict[str, Any]]:
    """A robot driving straight at a wall 1 m ahead: its x follows the gap."""
    return [{'t': i * step, 'gap': g, 'contact': g <= touching_below, 'x': 1.0 - g, 'y': 0.0,
             'yaw': 0.0, 'commands': i} for i, g in enumerate(gaps)]


def _wired(**extra: Any) -> dict[str, Any]:
    return {'scan_publishers': ('/ros_gz_bridge',), 'cmd_vel_publishers': ('/c',),
            'scan_subscribers': ('/c',), **extra}


@pytest.mark.no_ros
def test_a_stop_too_close_or_too_far_is_named() -> None:
    approach = [1.0 - 0.004 * i for i in range(150)]  # 0.4 m/s for 1.5 s
    close = TrialResult.from_samples(_samples(approach + [approach[-1]] * 60), **_wired())
    assert close.stopped and close.stopped_at == pytest.approx(1.5, abs=0.06)
    assert close.max_speed == pytest.approx(0.4, rel=0.01)
    assert judge_stop(close, 0.7, 0.05) == (
        False, 'stopped 0.40 m from the obstacle at t=1.5 s (sim time) (target 0.70 ± 0.05): '
        'too close')
    assert judge_stop(close, 0.2, 0.05)[1].endswith('too far')
    assert judge_stop(close, 0.4, 0.05)[0]


@pytest.mark.no_ros
def test_a_robot_still_moving_at_the_end_has_not_stopped() -> None:
    moving = TrialResult.from_samples(_samples([1.0 - 0.002 * i for i in range(100)]),
                                      **_wired())
    assert not moving.stopped and moving.stopped_at is None
    passed, line = judge_stop(moving, 0.3, 0.05)
    assert not passed and line.startswith('still moving at 0.20 m/s after 1.0 s of sim time')


@pytest.mark.no_ros
def test_commands_that_never_reach_the_simulator_name_the_missing_bridge() -> None:
    still = _samples([0.8] * 50)
    for sample in still:
        sample['commands'] = 0
    result = TrialResult.from_samples(still, bridged=False, **_wired())
    assert result.describe() == (
        '/cmd_vel never reached the simulator: it takes gz topic /cmd_vel; bridge it with: '
        'ros2 run ros_gz_bridge parameter_bridge /cmd_vel@geometry_msgs/msg/Twist]'
        'gz.msgs.Twist')


@pytest.mark.no_ros
def test_a_run_ends_at_the_sample_where_its_end_was_met() -> None:
    """However late the watcher reads them, the run is cut at the same sample."""
    from robot_lab.sim.trial_result import EndWatch, Speedometer

    def end(raw: list[dict[str, Any]]) -> tuple[float, str]:
        meter, watch = Speedometer(), EndWatch(0.5, 0.3, 0.02)
        for item in raw:
            found = watch.feed(meter.sample(item))
            if found is not None:
                return float(item['t']), found
        raise AssertionError('no end met')

    approach = [1.0 - 0.004 * i for i in range(150)]  # 0.4 m/s, then still from t=1.5 s
    t, why = end(_samples(approach + [approach[-1]] * 100))
    assert why == 'rest' and 2.0 <= t <= 2.1  # still (< 0.02 m/s over 50 ms) for 0.5 s
    crash = _samples([1.0 - 0.004 * i for i in range(300)], touching_below=0.2)
    t, why = end(crash)
    assert why == 'collision' and t == pytest.approx(2.0 + 0.3, abs=0.011)  # 0.2 m at 2.0 s
