"""An action server for the course: the Fibonacci action of the official tutorials.

The tutorials' example_interfaces is not on PyPI; test_msgs (which is) has the same
Fibonacci action: goal `order`, feedback and result `sequence`. One feedback message per
step, `step_period` seconds apart (parameter, default 0.5 s), so a client can watch it
grow and cancel it midway.
Try: `ros2 action send_goal --feedback /fibonacci test_msgs/action/Fibonacci "{order: 5}"`.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from rclpy.action.server import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from test_msgs.action import Fibonacci

from robot_lab.nodes.base import declare, run_node

__all__ = ['FibonacciNode', 'main']

class FibonacciNode(Node):
    """Serves /fibonacci (test_msgs/action/Fibonacci)."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('fibonacci_action_server', **kwargs)
        declare(self, 'step_period', 0.5, 'Seconds between feedback messages', (0.0, 10.0))
        self.server = ActionServer(
            self, Fibonacci, 'fibonacci', self.execute_callback,
            goal_callback=self.goal_callback, cancel_callback=self.cancel_callback,
            callback_group=ReentrantCallbackGroup(),
        )
        self.get_logger().info('Fibonacci action server started')

    def goal_callback(self, goal: Fibonacci.Goal) -> GoalResponse:
        if not 0 <= goal.order <= 46:  # fib(47) no longer fits an int32
            self.get_logger().warning(f'Rejecting goal: order {goal.order} not in 0..46')
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def cancel_callback(self, goal_handle: Any) -> CancelResponse:
        return CancelResponse.ACCEPT

    def execute_callback(self, goal_handle: Any) -> Fibonacci.Result:
        order = goal_handle.request.order
        self.get_logger().info(f'Executing goal: order {order}')
        period = float(self.get_parameter('step_period').value)
        sequence = [0, 1][:order + 1]
        feedback = Fibonacci.Feedback()
        for _ in range(order - 1):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                self.get_logger().info('Goal canceled')
                return Fibonacci.Result(sequence=sequence)
            sequence.append(sequence[-1] + sequence[-2])
            feedback.sequence = sequence
            goal_handle.publish_feedback(feedback)
            time.sleep(period)
        goal_handle.succeed()
        self.get_logger().info(f'Goal succeeded: {sequence}')
        return Fibonacci.Result(sequence=sequence)


def main(args: Sequence[str] | None = None) -> None:
    # Two threads: the execute callback sleeps between steps while cancel requests,
    # result requests and parameter services are still answered.
    run_node(FibonacciNode, args, threads=2)


if __name__ == '__main__':
    main()
