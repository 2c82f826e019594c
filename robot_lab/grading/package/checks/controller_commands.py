"""`controller_commands`: a node turns the sensor's readings into commands."""

from __future__ import annotations

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['controller_commands']

EXPECTED = 'a node that subscribes to the sensor topic and publishes commands derived from it'


@register('controller_commands', stage='run')
def controller_commands(state: JobState, check: RubricCheck) -> Verdict:
    live = state.live
    if (watched := live.watched()) is None:
        return live.not_run_verdict('the running system')
    obs, roles = watched
    if roles.sensor is None or roles.controller is None:
        why = '; '.join(roles.notes) or 'no node subscribes to a sensor topic and publishes'
        return Verdict(False, EXPECTED, why + '.\n\n' + live.seen(),
                       live.crash_fix() or "subscribe to exactly the sensor's topic name and "
                       'type (check with `ros2 topic list -t`), and publish a command from '
                       'the callback')
    commands = obs.topics.get(roles.command_topic or '')
    count = commands.count if commands else 0
    sample = commands.samples[-1] if commands and commands.samples else '(none)'
    observed = (f'controller `{roles.controller}` subscribes to `{roles.sensor_topic}` and '
                f'publishes `{roles.command_topic}`: {count} msgs in {obs.duration:.1f} s; '
                f'sample: `{sample}`')
    response = live.response
    if count == 0:
        return Verdict(False, EXPECTED, observed, 'publish a command in the sensor callback (or '
                       'a timer) computed from the latest reading')
    if response is None or not response.tested:
        # Not driven (nothing to imitate): the commands are all that can be judged.
        why = response.why if response is not None else 'not driven'
        return Verdict(True, EXPECTED, observed + f'\n\n(its response was not tested: {why})')
    observed += (f'\n\nThen {response.how}, low → high → low:\n\n' + response.table())
    if response.follows:
        return Verdict(True, EXPECTED, observed + '\n\nits commands follow the input')
    return Verdict(False, EXPECTED, observed + '\n\nits commands did not follow the input',
                   'compute each command from the latest reading (e.g. speed = gain × (distance '
                   '− target), capped), in the subscription callback or a timer that uses the '
                   'last value received')
