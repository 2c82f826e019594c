"""`sensor_publishes`: a node publishes simulated readings periodically: with no input, or
closing the loop by reading the commands it simulates the plant from (roles.py says which)."""

from __future__ import annotations

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict, code

__all__ = ['sensor_publishes']


@register('sensor_publishes', stage='run')
def sensor_publishes(state: JobState, check: RubricCheck) -> Verdict:
    live = state.live
    min_rate = float(check.option('min_rate_hz', 0.5))
    max_logs = float(check.option('max_log_rate_hz', 500))
    if (watched := live.watched()) is None:
        return live.not_run_verdict('the running system')
    obs, roles = watched
    if roles.sensor is None:
        return Verdict(False, f'a node that publishes a topic periodically (≥ {min_rate:g} Hz), '
                       'with no input or only the commands of its loop', live.seen(),
                       live.crash_fix() or 'create a timer (`create_timer(1.0 / rate, '
                       'callback)`) that publishes a message with a simulated reading')
    topic = obs.topics[roles.sensor_topic or '']
    sample = topic.samples[-1] if topic.samples else '(none kept)'
    flood = max(obs.log_rate(roles.sensor), live.line_rates.get(roles.sensor, 0.0))
    ok = flood <= max_logs
    return Verdict(
        ok, 'a node that publishes a topic periodically (its input, if any, the commands of '
        f'its loop), logging at most {max_logs:g} lines/s',
        f'sensor `{roles.sensor}` publishes `{topic.name}` '
        f'[{", ".join(topic.types)}] at {topic.rate:.1f} Hz; sample: `{sample}`'
        + ('' if ok else f'\n\nbut it logs {flood:.0f} lines/s; last lines:'
           + code(list(obs.nodes[roles.sensor].logs), 4)),
        'log at DEBUG, or throttle (`throttle_duration_sec=` on the logger), and never print '
        'in a loop')
