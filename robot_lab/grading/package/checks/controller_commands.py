"""`controller_commands`: a node turns the sensor's readings into commands."""

from __future__ import annotations

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.roles import controller_output_changes
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['controller_commands']

EXPECTED = 'a node that subscribes to the sensor topic and publishes commands derived from it'


@register('controller_commands', stage='run')
def controller_commands(state: JobState, check: RubricCheck) -> Verdict:
    live = state.live
    if live.not_run or live.obs is None or live.roles is None:
        return live.not_run_verdict('the running system')
    obs, roles = live.obs, live.roles
    if roles.sensor is None or roles.controller is None:
        why = '; '.join(roles.notes) or 'no node subscribes to a sensor topic and publishes'
        return Verdict(False, EXPECTED, why + '.\n\n' + live.seen(),
                       "subscribe to exactly the sensor's topic name and type (check with "
                       '`ros2 topic list -t`), and publish a command from the callback')
    commands = obs.topics.get(roles.command_topic or '')
    count = commands.count if commands else 0
    sample = commands.samples[-1] if commands and commands.samples else '(none)'
    changes = controller_output_changes(obs, roles)
    need_change = bool(check.option('require_change', False))
    ok = count > 0 and (changes or not need_change)
    return Verdict(
        ok, EXPECTED,
        f'controller `{roles.controller}` subscribes to `{roles.sensor_topic}` and publishes '
        f'`{roles.command_topic}`: {count} msgs in {obs.duration:.1f} s; sample: `{sample}`'
        + ('' if changes else '; every command was the same'),
        'publish a command in the sensor callback (or a timer) computed from the latest reading')
