"""turtlesim's simulation without ROS: the numbers and messages the tutorials rely on."""

from __future__ import annotations

import math

import pytest

from robot_lab.turtlesim import CANVAS, FRAME_PERIOD, RotateGoal, World
from robot_lab.turtlesim.path_image import PathImage
from robot_lab.turtlesim.turtle import normalize_angle

pytestmark = pytest.mark.no_ros  # reads files only: no ROS_DOMAIN_ID slot


class Log:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def info(self, message: str) -> None:
        self.lines.append(('info', message))

    def warning(self, message: str) -> None:
        self.lines.append(('warn', message))

    def error(self, message: str) -> None:
        self.lines.append(('error', message))

    def said(self, text: str) -> bool:
        return any(text in line for _, line in self.lines)


def frames(world: World, seconds: float, t0: float = 0.0) -> float:
    t = t0
    for _ in range(round(seconds / FRAME_PERIOD)):
        t += FRAME_PERIOD
        world.step(t)
    return t


@pytest.fixture
def world() -> World:
    w = World(logger=Log(), seed=1)
    w.start()
    return w


def log(world: World) -> Log:
    assert isinstance(world.logger, Log)
    return world.logger


def test_turtle1_starts_in_the_middle_facing_east(world: World) -> None:
    (state,), strokes = world.step(0.0)
    assert state.name == 'turtle1'
    assert f'{state.pose.x:f}' == '5.544445' and f'{state.pose.y:f}' == '5.544445'
    assert state.pose.theta == 0.0 and strokes == []
    assert log(world).said('Spawning turtle [turtle1] at x=[5.544445], y=[5.544445], '
                           'theta=[0.000000]')
    assert state.color == (255, 255, 255)  # nothing drawn: the transparent image's white


def test_a_command_moves_for_one_second_then_stops(world: World) -> None:
    world.turtles['turtle1'].command(2.0, 0.0, 1.8, now=0.0)
    t = frames(world, 0.5)
    moving = world.step(t)[0][0].pose
    assert moving.linear_velocity == 2.0 and moving.angular_velocity == 1.8
    t = frames(world, 1.0, t)
    stopped = world.step(t)[0][0].pose
    assert stopped.linear_velocity == 0.0 and stopped.angular_velocity == 0.0
    # integrated at the frame period: an arc of radius 2/1.8 m over about one second
    assert math.dist((moving.x, moving.y), (5.544445, 5.544445)) > 0.5
    later = world.step(frames(world, 0.5, t))[0][0].pose
    assert (later.x, later.y) == (stopped.x, stopped.y)


def test_the_pen_draws_and_the_color_sensor_sees_it(world: World) -> None:
    turtle = world.turtles['turtle1']
    turtle.command(1.0, 0.0, 0.0, now=0.0)
    _, strokes = world.step(FRAME_PERIOD)
    assert strokes and strokes[0][4:] == (0xb3, 0xb8, 0xff, 3)
    t = frames(world, 0.3)
    assert world.step(t)[0][0].color == (0xb3, 0xb8, 0xff)
    turtle.set_pen(255, 0, 0, 5, False)
    t = frames(world, 0.3, t)
    assert world.step(t)[0][0].color == (255, 0, 0)
    turtle.set_pen(0, 0, 0, 0, True)  # off: moves without drawing
    t = frames(world, 0.2, t)
    assert world.step(t)[1] == []
    turtle.set_pen(0, 255, 0, 0, False)  # width 0 → a new QPen's width, 1
    assert turtle.pen.width == 1 and turtle.pen.on
    world.clear()
    assert log(world).said('Clearing turtlesim.')
    assert world.image.pixel(turtle.x * 45, (CANVAS - turtle.y) * 45) == (255, 255, 255)


def test_walls_clamp_with_turtlesim_warning(world: World) -> None:
    world.turtles['turtle1'].command(8.0, 0.0, 0.0, now=0.0)
    t = frames(world, 0.9)
    pose = world.step(t)[0][0].pose
    assert pose.x == pytest.approx(CANVAS) and pose.y == pytest.approx(5.544445)
    warning = next(line for level, line in log(world).lines if level == 'warn')
    assert warning.startswith('Oh no! I hit the wall! (Clamping from [x=11.')
    assert warning.endswith(', y=5.544444])')  # turtlesim prints the image's y (down)


def test_spawn_names_kill_and_reset(world: World) -> None:
    assert world.spawn('', 2.0, 2.0, 0.2) is not None
    assert sorted(world.turtles) == ['turtle1', 'turtle2']
    assert world.spawn('turtle2', 1.0, 1.0, 0.0) is None
    assert log(world).said('A turtle named [turtle2] already exists')
    assert world.spawn('leonardo', 1.0, 1.0, 0.0) is not None
    assert world.kill('turtle2') and not world.kill('turtle2')
    assert log(world).said('Tried to kill turtle [turtle2], which does not exist')
    assert world.spawn('', 3.0, 3.0, 0.0).name == 'turtle3'  # type: ignore[union-attr]
    world.turtles['turtle1'].teleport_absolute(1.0, 1.0, 0.0)
    world.step(0.1)
    world.reset()
    assert list(world.turtles) == ['turtle1']
    (state,), _ = world.step(0.2)
    assert (round(state.pose.x, 6), round(state.pose.y, 6)) == (5.544445, 5.544445)
    assert world.spawn('', 1.0, 1.0, 0.0).name == 'turtle2'  # type: ignore[union-attr]


def test_teleports_absolute_and_relative(world: World) -> None:
    turtle = world.turtles['turtle1']
    turtle.teleport_absolute(1.0, 2.0, 1.57)
    (state,), strokes = world.step(0.0)
    assert (state.pose.x, state.pose.y, state.pose.theta) == (1.0, 2.0, 1.57)
    assert len(strokes) == 1  # the pen draws the jump, as turtlesim's does
    turtle.teleport_relative(2.0, -1.57)
    (state,), _ = world.step(0.0)
    assert state.pose.x == pytest.approx(3.0) and state.pose.y == pytest.approx(2.0)
    turtle.teleport_absolute(5.0, 20.0, 0.0)  # above the top: the top edge
    (state,), _ = world.step(0.0)
    assert state.pose.y == pytest.approx(CANVAS)


def test_rotate_absolute_feedback_success_cancel_and_abort(world: World) -> None:
    turtle = world.turtles['turtle1']
    feedback: list[float] = []
    goal = RotateGoal(1.57, 0.0, on_feedback=feedback.append)
    turtle.rotate(goal)
    t = 0.0
    while not goal.done.is_set() and t < 5:
        t += FRAME_PERIOD
        world.step(t)
    assert goal.outcome == 'succeeded'
    assert feedback[0] == pytest.approx(1.57) and abs(feedback[-1]) < 0.02
    assert goal.delta == pytest.approx(-1.57, abs=0.03)  # start - end, as turtlesim reports
    assert log(world).said('Rotation goal completed successfully')
    cancel = {'now': False}
    second = RotateGoal(-1.57, 0.0, is_canceling=lambda: cancel['now'])
    turtle.rotate(second)
    t = frames(world, 0.3, t)
    cancel['now'] = True
    world.step(t + FRAME_PERIOD)
    assert second.outcome == 'canceled' and log(world).said('Rotation goal canceled')
    third = RotateGoal(3.0, 0.0)
    turtle.rotate(third)
    fourth = RotateGoal(0.0, 0.0)
    turtle.rotate(fourth)
    assert third.outcome == 'aborted'
    assert log(world).said('Rotation goal received before a previous goal finished')
    turtle.command(1.0, 0.0, 0.0, now=t)
    assert fourth.outcome == 'aborted'
    assert log(world).said('Velocity command received during rotation goal. Aborting goal')


def test_holonomic_only_when_asked(world: World) -> None:
    turtle = world.turtles['turtle1']
    turtle.command(0.0, 1.0, 0.0, now=0.0)
    (state,), _ = world.step(FRAME_PERIOD)
    assert state.pose.y == pytest.approx(5.544445)
    turtle.command(0.0, 1.0, 0.0, now=0.0, holonomic=True)
    (state,), _ = world.step(2 * FRAME_PERIOD)
    assert state.pose.y == pytest.approx(5.544445 + FRAME_PERIOD)


def test_normalize_angle_range() -> None:
    assert normalize_angle(math.pi) == pytest.approx(-math.pi)
    assert normalize_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert normalize_angle(-0.5) == -0.5


def test_path_image_png_is_readable() -> None:
    image = PathImage(size=20)
    image.line(2, 2, 15, 2, (255, 0, 0), 3)
    assert image.pixel(8, 2) == (255, 0, 0) and image.pixel(8, 6) == (255, 255, 255)
    png = image.png()
    assert png.startswith(b'\x89PNG') and png.endswith(b'IEND\xaeB`\x82')
