"""`controller_commands`: a node turns the sensor's readings into commands.

The commands may be of any type (robot_lab.grading.package.perturb reads every field), so
the advice for a controller that does not follow its input fits what it publishes: a
speed formula for a Twist, a threshold for a Bool lamp switch, a level or a state name for
an integer or a string, the fields to set for a message of the student's own.
"""

from __future__ import annotations

from typing import Any

from robot_lab.grading.package.perturb import Value, command_fields
from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['command_hint', 'controller_commands']

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
    if response is not None and response.fault:
        return Verdict(False, EXPECTED, observed, grader_error='driving the sensor topic '
                       f'failed: {response.fault}')
    if response is None or not response.tested:
        # Not driven (nothing to imitate): the commands are all that can be judged.
        why = response.why if response is not None else 'not driven'
        return Verdict(True, EXPECTED, observed + f'\n\n(its response was not tested: {why})')
    observed += (f'\n\nThen {response.how}, low → high → low:\n\n' + response.table())
    changed = response.changed()
    moved = ('fields that changed with the input: ' + ', '.join(f'`{k}`' for k in changed[:8])
             if changed else 'no field of the command changed with the input')
    if response.follows:
        return Verdict(True, EXPECTED, observed + f'\n\nits commands follow the input ({moved})')
    last = commands.values[-1] if commands and commands.values else {}
    return Verdict(False, EXPECTED,
                   observed + f'\n\nits commands did not follow the input ({moved})',
                   command_hint(commands.types[0] if commands and commands.types else '',
                                last))


def command_hint(type_name: str, last: dict[str, Any]) -> str:
    """How to make commands of this type follow the reading (`last`: a command's dict)."""
    fields = dict(command_fields(last))
    where = ('in the subscription callback, or in a timer that uses the last value '
             'received, so that each command comes from the latest reading')
    kinds = {_kind(v) for v in fields.values()}
    short = type_name.rsplit('/', 1)[-1]
    if short in ('Twist', 'TwistStamped', 'Accel', 'AccelStamped') or (
            kinds == {'number'} and any(k.startswith(('linear', 'angular')) for k in fields)):
        return ('compute each command from the latest reading (e.g. speed = gain × '
                f'(distance − target), capped), {where}')
    names = ', '.join(f'`{k}`' for k in list(fields)[:4]) or 'its fields'
    if kinds == {'bool'}:
        return (f'set {names} from the latest reading against a threshold (e.g. '
                '`msg.data = reading < threshold`; with hysteresis, switch on below one '
                f'threshold and off above a higher one), {where}')
    if kinds == {'text'}:
        return (f"choose the state ({names}) from the latest reading (e.g. `'ON' if "
                f"reading < threshold else 'OFF'`), {where}")
    if kinds == {'integer'}:
        return (f'choose the level ({names}) from the latest reading (e.g. `0 if reading '
                f'< low else 1 if reading < high else 2`), {where}')
    if kinds == {'number'}:
        return (f'compute {names} from the latest reading (e.g. gain × (reading − '
                f'target), capped), {where}')
    return (f'set the fields of your `{short or "command"}` message ({names}) from the '
            f'latest reading, {where}')


def _kind(value: Value | int) -> str:
    if isinstance(value, bool):
        return 'bool'
    if isinstance(value, str):
        return 'text'
    return 'integer' if isinstance(value, int) else 'number'
