"""`actuator_logs`: a node receives the commands and logs each one."""

from __future__ import annotations

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict, code

__all__ = ['actuator_logs']


@register('actuator_logs', stage='run')
def actuator_logs(state: JobState, check: RubricCheck) -> Verdict:
    live = state.live
    if (watched := live.watched()) is None:
        return live.not_run_verdict('the running system')
    obs, roles = watched
    if roles.sensor is None or roles.controller is None:
        return Verdict(False, 'a node that subscribes to the commands and logs each one',
                       'no commands to log: there is no controller output.\n\n' + live.seen(),
                       live.crash_fix() or 'first make the controller publish commands')
    expected = f'a node that subscribes to `{roles.command_topic}` and logs each command'
    if roles.actuator is None:
        return Verdict(False, expected, 'no other node subscribes to it.\n\n' + live.seen(),
                       live.crash_fix() or f'subscribe to `{roles.command_topic}` with the same '
                       'type and call `self.get_logger().info(...)` in the callback')
    commands = obs.topics.get(roles.command_topic or '')
    count = commands.count if commands else 0
    node = obs.nodes[roles.actuator]
    fraction = float(check.option('min_log_fraction', 0.5))
    ok = count > 0 and node.log_count >= max(1.0, fraction * count)
    return Verdict(
        ok, expected, f'actuator `{roles.actuator}` received {count} commands and logged '
        f'{node.log_count} lines; its last log lines:'
        + (code(list(node.logs), 5) if node.logs else ' (none)') + live.dead(),
        'call `self.get_logger().info(f"...{msg}")` in the subscription callback')
