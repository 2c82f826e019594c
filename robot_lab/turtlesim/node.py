"""`ros2 run turtlesim turtlesim_node`: the /turtlesim node over the simulation (`world`).

Names, types, QoS and log lines as Jazzy's turtlesim: per turtle `<name>/cmd_vel`,
`<name>/pose`, `<name>/color_sensor` (reliable, depth 7), the services `<name>/set_pen`,
`<name>/teleport_absolute|relative` and the action `<name>/rotate_absolute`; node-wide
`clear`, `reset`, `spawn`, `kill` and the parameters `background_r|g|b` and `holonomic`.

There is no Qt window. What a window would draw goes out on two hidden names (a leading
`_`, so `topic list` and `bag record -a` leave them out as they leave out any hidden
topic): `~/_view` (std_msgs/String, JSON: background, turtles, new pen strokes, ~20 a second
while someone watches) and `~/_snapshot` (std_srvs/Trigger: the trails so far as a PNG),
so a notebook can watch a turtlesim started in a terminal (`robot_lab.turtlesim_view()`).
"""

from __future__ import annotations

import base64
import json
from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import Twist
from rcl_interfaces.msg import IntegerRange, ParameterDescriptor, ParameterEvent
from rclpy.action.server import ActionServer, CancelResponse, GoalResponse
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.task import Future
from std_msgs.msg import String
from std_srvs.srv import Empty, Trigger
from turtlesim.action import RotateAbsolute
from turtlesim.msg import Color, Pose
from turtlesim.srv import Kill, SetPen, Spawn, TeleportAbsolute, TeleportRelative

from robot_lab.nodes.base import run_node
from robot_lab.turtlesim.cpp_node import CppNode
from robot_lab.turtlesim.turtle import RotateGoal, Segment, Turtle
from robot_lab.turtlesim.world import FRAME_PERIOD, World

__all__ = ['TurtlesimNode', 'main', 'topic_qos']

VIEW_EVERY = 3  # frames between view messages: ~20 a second


def topic_qos() -> QoSProfile:
    """turtlesim's topic_qos(): reliable, keep last 7 (all its publishers and subscribers)."""
    return QoSProfile(depth=7, reliability=ReliabilityPolicy.RELIABLE)


class _TurtleEndpoints:
    """One turtle's subscription, publishers, services and action server."""

    def __init__(self, node: TurtlesimNode, turtle: Turtle) -> None:
        name, qos = turtle.name, topic_qos()
        self.node = node
        self.cmd_vel = node.create_subscription(
            Twist, f'{name}/cmd_vel', lambda msg: node.on_cmd_vel(turtle, msg), qos)
        self.pose = node.create_publisher(Pose, f'{name}/pose', qos)
        self.color = node.create_publisher(Color, f'{name}/color_sensor', qos)
        self.services = [
            node.create_service(SetPen, f'{name}/set_pen', lambda req, res: _set_pen(
                turtle, req, res)),
            node.create_service(TeleportRelative, f'{name}/teleport_relative',
                                lambda req, res: _teleport_relative(turtle, req, res)),
            node.create_service(TeleportAbsolute, f'{name}/teleport_absolute',
                                lambda req, res: _teleport_absolute(turtle, req, res)),
        ]
        async def execute(handle: Any) -> RotateAbsolute.Result:  # a coroutine for rclpy
            return await node.execute_rotation(turtle, handle)

        self.rotate = ActionServer(
            node, RotateAbsolute, f'{name}/rotate_absolute', execute,
            goal_callback=lambda _goal: GoalResponse.ACCEPT,
            cancel_callback=lambda _handle: CancelResponse.ACCEPT)

    def destroy(self) -> None:
        node = self.node
        node.destroy_subscription(self.cmd_vel)
        node.destroy_publisher(self.pose)
        node.destroy_publisher(self.color)
        for service in self.services:
            node.destroy_service(service)
        self.rotate.destroy()


def _set_pen(turtle: Turtle, req: Any, res: Any) -> Any:
    turtle.set_pen(req.r, req.g, req.b, req.width, bool(req.off))
    return res


def _teleport_relative(turtle: Turtle, req: Any, res: Any) -> Any:
    turtle.teleport_relative(req.linear, req.angular)
    return res


def _teleport_absolute(turtle: Turtle, req: Any, res: Any) -> Any:
    turtle.teleport_absolute(req.x, req.y, req.theta)
    return res


class TurtlesimNode(CppNode):
    """/turtlesim: a World stepped every 16 ms, its turtles' topics, services and actions."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('turtlesim', **kwargs)
        channel = IntegerRange(from_value=0, to_value=255, step=1)
        for letter, colour, default in (('r', 'Red', 0x45), ('g', 'Green', 0x56),
                                        ('b', 'Blue', 0xff)):
            self.declare_parameter(f'background_{letter}', default, ParameterDescriptor(
                description=f'{colour} channel of the background color',
                integer_range=[channel]))
        self.declare_parameter('holonomic', False, ParameterDescriptor(
            description='If true, then turtles will be holonomic'))
        self._endpoints: dict[str, _TurtleEndpoints] = {}
        self._strokes: list[Segment] = []
        self._generation = 0
        self._frames = 0
        self.world = World(logger=self.get_logger(), on_spawn=self._open, on_kill=self._close)
        self.create_service(Empty, 'clear', self._on_clear)
        self.create_service(Empty, 'reset', self._on_reset)
        self.create_service(Spawn, 'spawn', self._on_spawn)
        self.create_service(Kill, 'kill', self._on_kill)
        # turtle_frame repaints on its own parameter events (the background colour); the
        # view sends the background with every message, this keeps the graph as upstream's
        self.create_subscription(ParameterEvent, '/parameter_events', lambda _msg: None,
                                 QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT))
        self.view = self.create_publisher(String, '~/_view', 10)
        self.create_service(Trigger, '~/_snapshot', self._on_snapshot)
        self.get_logger().info(
            f'Starting turtlesim with node name {self.get_fully_qualified_name()}')
        self.world.start(self._now())
        self.create_timer(FRAME_PERIOD, self._frame)

    def _now(self) -> float:
        return float(self.get_clock().now().nanoseconds) * 1e-9

    # -- turtles' endpoints (World calls these under its lock) ------------------------
    def _open(self, turtle: Turtle) -> None:
        self._endpoints[turtle.name] = _TurtleEndpoints(self, turtle)

    def _close(self, turtle: Turtle) -> None:
        endpoints = self._endpoints.pop(turtle.name, None)
        if endpoints is not None:
            endpoints.destroy()

    # -- callbacks --------------------------------------------------------------------
    def on_cmd_vel(self, turtle: Turtle, msg: Twist) -> None:
        holonomic = bool(self.get_parameter('holonomic').value)
        turtle.command(msg.linear.x, msg.linear.y, msg.angular.z, self._now(), holonomic)

    async def execute_rotation(self, turtle: Turtle, handle: Any) -> RotateAbsolute.Result:
        """Waits (without a thread) until the frame ends the goal: reached, canceled or
        aborted. Everything runs on the node's one executor thread, as turtlesim's Qt loop
        does, so a goal, a command and a frame never interleave."""
        def feedback(remaining: float) -> None:
            handle.publish_feedback(RotateAbsolute.Feedback(remaining=remaining))

        finished = Future()
        goal = RotateGoal(handle.request.theta, 0.0,
                          is_canceling=lambda: bool(handle.is_cancel_requested),
                          on_feedback=feedback, on_finish=finished.set_result)
        turtle.rotate(goal)
        await finished
        result = RotateAbsolute.Result(delta=goal.delta)
        if goal.outcome == 'succeeded':
            handle.succeed()
        elif goal.outcome == 'canceled':
            handle.canceled()
        else:
            handle.abort()
        return result

    def _on_clear(self, _req: Empty.Request, res: Empty.Response) -> Empty.Response:
        self.world.clear()
        self._generation += 1
        self._strokes = []
        return res

    def _on_reset(self, _req: Empty.Request, res: Empty.Response) -> Empty.Response:
        self.world.reset(self._now())
        self._generation += 1
        self._strokes = []
        return res

    def _on_spawn(self, req: Spawn.Request, res: Spawn.Response) -> Spawn.Response:
        turtle = self.world.spawn(req.name, req.x, req.y, req.theta, self._now())
        res.name = turtle.name if turtle is not None else ''
        return res

    def _on_kill(self, req: Kill.Request, res: Kill.Response) -> Kill.Response:
        self.world.kill(req.name)
        return res

    def _on_snapshot(self, _req: Trigger.Request, res: Trigger.Response) -> Trigger.Response:
        generation = self._generation
        picture = base64.b64encode(self.world.picture()).decode('ascii')
        res.success = True
        res.message = json.dumps({'png': picture, 'gen': generation, **self._scene()})
        return res

    # -- the frame --------------------------------------------------------------------
    def _frame(self) -> None:
        states, strokes = self.world.step(self._now())
        for state in states:
            endpoints = self._endpoints.get(state.name)
            if endpoints is None:
                continue
            x, y, theta, linear, angular = state.pose
            endpoints.pose.publish(Pose(x=x, y=y, theta=theta, linear_velocity=linear,
                                        angular_velocity=angular))
            r, g, b = state.color
            endpoints.color.publish(Color(r=r, g=g, b=b))
        self._frames += 1
        watched = self.view.get_subscription_count() > 0
        if watched:
            self._strokes.extend(strokes)
        else:
            self._strokes.clear()
        if watched and self._frames % VIEW_EVERY == 0:
            strokes, self._strokes = self._strokes, []
            self.view.publish(String(data=json.dumps({
                'gen': self._generation, **self._scene(),
                'strokes': [[round(v, 4) for v in s] for s in strokes]})))

    def _scene(self) -> dict[str, Any]:
        turtles = [[name, round(x, 4), round(y, 4), round(theta, 4), image]
                   for name, x, y, theta, image in self.world.scene()]
        background = [int(self.get_parameter(f'background_{c}').value) for c in 'rgb']
        return {'background': background, 'turtles': turtles}


def main(args: Sequence[str] | None = None) -> None:
    """The `turtlesim_node` executable."""
    run_node(TurtlesimNode, args)


if __name__ == '__main__':
    main()
