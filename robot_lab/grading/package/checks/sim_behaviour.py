"""`sim_behaviour` (run): the student's controller drives a robot in the kit's simulator.

The assignment names a behaviour; the kit grades `stop_before_obstacle` (Chapter 6's
controller against `/scan`, Module 2): the robot starts facing a wall (or in a world the
rubric names), the package's controller runs (the launch file the rest of the rubric ran,
or the one `launch:`/`executable:` names), and the simulator's ground truth
(`robot_lab.sim.trial`) says where the robot's collision geometry stopped and whether it
touched the obstacle. The robot is the package's own URDF/xacro when it has one (`robot:`
a path picks one; `robot: sample` the kit's sample robot), else the kit's sample robot.
The grader bridges /scan, /cmd_vel, /odom and /clock unless `bridge: false`: then the
student's launch must start its parameter_bridge (it gets the simulator's GZ_PARTITION).
The simulation runs in lockstep (`lockstep: false` to run it free): after each scan it waits
for the controller's answer, so a loaded grading host does not turn a student's latency
into a crash. A simulator that fails to start, or a job out of time, is the grader's
error, never the student's loss.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import RobotLabError
from robot_lab.grading.package.checks.description import _xacro, description_files
from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict, code

if TYPE_CHECKING:
    from robot_lab.launch.plan import LaunchPlan
    from robot_lab.sim.trial import TrialResult

__all__ = ['sim_behaviour', 'validate']

BEHAVIOURS = ('stop_before_obstacle',)
_NUMBERS = {'target': 0.3, 'tolerance': 0.05, 'obstacle_distance': 1.0, 'sim_seconds': 15.0,
            'wall_seconds': 60.0, 'speed': 1.0}
_TEXTS = ('behaviour', 'world', 'robot', 'launch', 'executable')
_OPTIONS = {*_NUMBERS, *_TEXTS, 'obstacle', 'spawn', 'bridge', 'require_sim_time', 'lockstep'}
_SYSTEMS = ('lidar (a gpu_lidar sensor)', 'DiffDrive system')
_RESERVE = 20.0  # job seconds kept for writing the report after this check


def validate(options: Mapping[str, Any]) -> tuple[str, str, str] | None:
    """(the option, what is wrong, the fix) for a rubric entry's options, else None."""
    unknown = sorted(set(options) - _OPTIONS)
    if unknown:
        return (unknown[0], f'unknown option(s) {", ".join(unknown)}',
                f'use: {", ".join(sorted(_OPTIONS))}')
    behaviour = options.get('behaviour', BEHAVIOURS[0])
    if behaviour not in BEHAVIOURS:
        return ('behaviour', f'behaviour {behaviour!r} is not one the kit grades',
                f'write `behaviour: {BEHAVIOURS[0]}`')
    for key in _NUMBERS:
        value = options.get(key, _NUMBERS[key])
        if isinstance(value, bool) or not isinstance(value, int | float) or value <= 0:
            return (key, f'{key} must be a number > 0 (got {value!r})',
                    f'write e.g. `{key}: {_NUMBERS[key]}`')
    for key in _TEXTS:
        if key in options and not isinstance(options[key], str):
            return key, f'{key} must be a text (got {options[key]!r})', f'write e.g. `{key}: ...`'
    if 'launch' in options and 'executable' in options:
        return ('executable', 'give `launch` or `executable`, not both',
                'keep the one the controller runs by')
    for key in ('bridge', 'require_sim_time', 'lockstep'):
        if not isinstance(options.get(key, True), bool):
            return key, f'{key} must be true or false', f'write `{key}: true`'
    spawn = options.get('spawn', [0.0, 0.0, 0.0])
    if not (isinstance(spawn, list) and len(spawn) == 3
            and all(isinstance(v, int | float) for v in spawn)):
        return 'spawn', 'spawn must be [x, y, yaw]', 'write e.g. `spawn: [0.0, 0.0, 0.0]`'
    obstacle = options.get('obstacle', [])
    if not isinstance(obstacle, str | list):
        return ('obstacle', 'obstacle must be a model name or a list of them',
                'write e.g. `obstacle: wall`')
    if (options.get('world', 'wall') == 'wall' and float(options.get('obstacle_distance', 1.0))
            <= float(options.get('target', 0.3))):
        return ('obstacle_distance', 'obstacle_distance must be more than target (the robot '
                'starts farther from the wall)', 'write e.g. `obstacle_distance: 1.0`')
    return None


def _robot(state: JobState, check: RubricCheck) -> tuple[str | None, str]:
    """(URDF text or None for the kit's sample robot, what it is, for feedback)."""
    assert state.package is not None
    wanted = check.option('robot', '')
    if wanted == 'sample':
        return None, "the kit's sample robot"
    files = description_files(state.package, wanted or None)
    if not files:
        if wanted:
            raise RobotLabError(f'no file {wanted} in the package',
                                fix='hand in the robot description the assignment asks for')
        return None, "the kit's sample robot (the package has no URDF)"
    path = files[0]
    rel = str(path.relative_to(state.package))
    text = _xacro(path, state) if path.name.endswith('.xacro') else path.read_text()
    return text, f'your robot ({rel})'


def _missing_systems(urdf: str | None) -> list[str]:
    """What the robot lacks to be driven against /scan, read from its `<gazebo>` tags (the
    simulator says it again once it has spawned it; XML it cannot read is its to refuse)."""
    from robot_lab.sim.gazebo_tags import read_gazebo_tags
    from robot_lab.sim.xml_tree import SimulationError, parse

    if urdf is None:
        return []
    try:
        tags = read_gazebo_tags(parse(urdf, 'robot'), lambda line: None)
    except SimulationError:
        return []
    return [what for what, has in zip(_SYSTEMS, (tags.lidars, tags.diff_drives), strict=True)
            if not has]


def _plan(state: JobState, check: RubricCheck, folder: Path) -> LaunchPlan:
    """The controller's launch: the one named, else the rubric's, else the one executable."""
    from robot_lab.launch.api import describe_launch
    from robot_lab.pkg.index import executables

    package = state.package_name
    executable = check.option('executable', '')
    launch = check.option('launch', '') or state.live.launch_name
    if not executable and not launch:
        names = executables(package)
        if len(names) != 1:
            raise RobotLabError('the grader cannot tell which program is the controller '
                                f'(executables: {", ".join(names) or "none"})',
                                fix='add a launch file that starts the controller')
        executable = names[0]
    if executable:
        stand_in = folder / 'controller.launch.xml'
        stand_in.write_text(f'<launch>\n  <node pkg="{package}" exec="{executable}" '
                            f'output="screen"/>\n</launch>\n')
        return describe_launch(stand_in)
    return describe_launch(package, launch)


def _fix(result: TrialResult, bridged: bool, target: float) -> str:
    if result.wiring_problem() is not None:
        if not result.scan_publishers and not bridged:
            return ("start ros_gz_bridge's parameter_bridge in your launch file for /scan "
                    '(and /cmd_vel) as the Gazebo docs write it')
        if not result.cmd_vel_publishers:
            return 'publish geometry_msgs/msg/Twist on /cmd_vel from your controller'
        return 'publish on /cmd_vel as the scans arrive (check the topic names and the bridge)'
    if result.collision or not result.stopped:
        return (f'slow down as the obstacle nears and publish a zero Twist once it is '
                f'{target:.2f} m away; the scan measures from the lidar, not from the '
                "robot's front: add the lidar's distance to the front")
    if result.sim_time_ok is False:
        return (result.sim_time_problem() or '') + ' (in your launch file: '\
            "parameters=[{'use_sim_time': True}])"
    return ("compare the beam straight ahead (angle 0) with the target plus the lidar's "
            "distance to the robot's front")


def _observed(result: TrialResult, robot: str, logs: str, line: str) -> str:
    detail = (f'{line}\n\n{robot}; ground truth from the simulator: started '
              f'{result.start_distance:.2f} m away, came within '
              f'{max(result.min_distance, 0.0):.2f} m, top speed {result.max_speed:.2f} m/s, '
              f'{result.commands} commands taken in {result.sim_seconds:.1f} s of sim time')
    return detail + logs


@register('sim_behaviour', stage='run', validate=validate)
def sim_behaviour(state: JobState, check: RubricCheck) -> Verdict:
    from robot_lab.sim.trial import Trial, judge_stop, wall_ahead_sdf
    from robot_lab.sim.xml_tree import SimulationError

    target = float(check.option('target', _NUMBERS['target']))
    tolerance = float(check.option('tolerance', _NUMBERS['tolerance']))
    expected = (f'your controller drives the robot forward and stops it {target:.2f} ± '
                f'{tolerance:.2f} m before the obstacle without touching it (measured by the '
                "simulator from the robot's collision geometry)")
    if not state.built or state.package is None:
        return Verdict(False, expected, 'not run: the package does not build (see "builds")',
                       'fix the build')
    budget = state.time_left() - _RESERVE  # the simulator and bridge's start, then the run
    starting = min(60.0, budget / 4)  # each of the two
    wall = min(float(check.option('wall_seconds', _NUMBERS['wall_seconds'])),
               budget - 2 * starting)
    if wall < 10 or starting < 5:
        return Verdict(False, expected, 'not run', grader_error='the job had no time left '
                       'for the simulation')
    try:
        urdf, robot = _robot(state, check)
    except RobotLabError as err:
        return Verdict(False, expected, f'the robot could not be read: {err}', err.fix or '')
    missing = _missing_systems(urdf)
    if missing:
        return Verdict(False, expected, f'{robot} has no {" and no ".join(missing)}',
                       'add the <gazebo> tags of Module 2 to the URDF')
    world: str = check.option('world', 'wall')
    distance = float(check.option('obstacle_distance', _NUMBERS['obstacle_distance']))
    obstacle = check.option('obstacle', None)
    words = 'the wall' if world == 'wall' else 'the obstacle'
    if world == 'wall':
        world = wall_ahead_sdf(distance)
        obstacle = obstacle or 'wall'
    elif (state.package / world).is_file():
        world = str(state.package / world)
    x, y, yaw = (float(v) for v in check.option('spawn', [0.0, 0.0, 0.0]))
    bridged = bool(check.option('bridge', True))
    folder = Path(tempfile.mkdtemp(prefix='robot_lab_sim_check_'))
    trial = Trial(world, urdf, obstacles=[obstacle] if isinstance(obstacle, str) else obstacle,
                  xy=(x, y), yaw=yaw, bridge=bridged,
                  speed=float(check.option('speed', _NUMBERS['speed'])),
                  lockstep=bool(check.option('lockstep', True)))
    handle = None
    try:
        try:
            trial.start(timeout=starting)
        except SimulationError as err:
            if trial.failed == 'robot' and urdf is not None:  # it refused the student's robot
                return Verdict(False, expected, f'{robot} could not be spawned: '
                               f'{trial.failure}', 'run it in the simulator yourself (`ros2 '
                               'run ros_gz_sim create -file ...`) and fix what it names')
            return Verdict(False, expected, 'not run', grader_error=f'the simulator: {err}')
        missing = [what for what, topics in zip(_SYSTEMS, ('scan_topics', 'cmd_topics'),
                                                strict=True) if not trial.ready.get(topics)]
        if missing:
            return Verdict(False, expected, f'{robot} has no {" and no ".join(missing)}',
                           'add the <gazebo> tags of Module 2 to the URDF')
        try:
            plan = _plan(state, check, folder)
        except RobotLabError as err:
            return Verdict(False, expected, f'the controller could not be started: {err}',
                           err.fix or '')
        for spec in plan.processes():  # a bridge of the student's reaches this simulator
            spec.env['GZ_PARTITION'] = trial.partition
        from robot_lab.launch.api import LaunchHandle

        try:
            handle = LaunchHandle(plan)
        except RobotLabError as err:
            return Verdict(False, expected, f'the launch did not start: {err}',
                           err.fix or 'run it yourself with `ros2 launch` and fix its error')
        result = trial.run(float(check.option('sim_seconds', _NUMBERS['sim_seconds'])), wall,
                           controller_timeout=state.rubric.startup_seconds)
        logs = ''
        for process in handle.processes:
            if process.exit_code not in (None, 0):
                lines = [line for line in handle.logs(process.label) if line.strip()][-8:]
                logs += f'\n\n`{process.label}` exited with code {process.exit_code}:' + \
                    code(lines, 8)
    except SimulationError as err:
        return Verdict(False, expected, 'not run', grader_error=f'the simulator: {err}')
    finally:
        if handle is not None:
            handle.shutdown(timeout=10)
        trial.close()
        shutil.rmtree(folder, ignore_errors=True)
    if result.ended == 'wall_time' and result.sim_seconds < 1.0:
        return Verdict(False, expected, _observed(result, robot, logs, result.describe(words)),
                       grader_error='the simulation ran too slowly to judge (wall-clock limit)')
    passed, line = judge_stop(result, target, tolerance, obstacle=words,
                              require_sim_time=bool(check.option('require_sim_time', True)))
    return Verdict(passed, expected, _observed(result, robot, logs, line),
                   '' if passed else _fix(result, bridged, target))
