"""`params_used`: the launch loads the parameter file and the running nodes hold its values."""

from __future__ import annotations

import contextlib
import math
from typing import Any

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['params_used']

EXPECTED = 'the launch file loads the parameter file and the running nodes hold its values'


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        with contextlib.suppress(TypeError, ValueError):
            return math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=1e-9)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


@register('params_used', stage='run')
def params_used(state: JobState, check: RubricCheck) -> Verdict:
    live = state.live
    if live.not_run:
        return live.not_run_verdict('the running system')
    if not live.params_loaded:
        verdict = Verdict(
            False, EXPECTED, "the launch file passes none of the package's parameter files to "
            'a node', 'load it in the launch file: XML `<param from="$(find-pkg-share PKG)/'
            'config/params.yaml"/>` inside each `<node>`, Python `parameters=[os.path.join('
            "get_package_share_directory('PKG'), 'config', 'params.yaml')]`")
    else:
        checked, wrong, lines, unread = 0, 0, [], []
        dead = {p.name for p in live.died()}
        for reading in live.readings:
            named = reading.pattern.lstrip('/') not in ('**', '*')
            if reading.error and reading.node in live.alive_nodes and reading.node not in dead:
                # The node is up but the grader's read failed (a timeout): not a wrong value.
                unread.append(f'{reading.node} {reading.name}')
                lines.append(f'{reading.node} {reading.name}: the grader could not read it '
                             f'({reading.error})')
                continue
            if reading.node is None:
                # A node the file names that is not running (it died): nothing uses it.
                wrong += named
                lines.append(f'{reading.pattern} {reading.name}: no running node holds it')
                continue
            if reading.node in dead or reading.node not in live.alive_nodes:
                wrong += 1
                lines.append(f'{reading.node} {reading.name}: its node died, so the value is '
                             'not used')
                continue
            checked += 1
            if _same(reading.held, reading.file_value):
                lines.append(f'{reading.node} {reading.name} = {reading.held!r} '
                             f'(file: {reading.file_value!r})')
            else:
                wrong += 1
                lines.append(f'{reading.node} {reading.name} = {reading.held!r}, but the file '
                             f'says {reading.file_value!r}')
        observed = ('read back from the running nodes:\n\n'
                    + '\n'.join(f'- `{x}`' for x in lines[:12])
                    if lines else 'the file gave the nodes no parameter to check')
        verdict = Verdict(checked > 0 and wrong == 0, EXPECTED, observed,
                          'declare each parameter in the node (`declare_parameter(name, '
                          'default)`) and read it with `get_parameter(name).value`; make the '
                          'node names in the file match the names the launch file gives')
        if not verdict.fraction and live.crash_fix():
            verdict.fix = live.crash_fix()
        if unread and wrong == 0:  # only the grader's failed reads stand in the way
            verdict.grader_error = (f'{len(unread)} parameter read(s) failed after retries: '
                                    + ', '.join(unread[:4]))
    if live.dropped:
        verdict.observed += ('\n\nleft out of the launch (rcl would refuse them, and every node '
                             'given them would exit at start):\n\n') + '\n'.join(
            f'- {d}' for d in live.dropped)
        verdict.fix = 'make the parameter file valid first (see the parameter file check)'
    return verdict
