"""Which of a controller's commands answer a level the grader drives (perturb._answered):
the first steady run that differs from the last level's, never a queue of older input."""

from __future__ import annotations

from robot_lab.grading.package.perturb import (
    _SAMPLES,
    Response,
    Sample,
    _answered,
    _at_level,
    _varying,
)


def _cmds(*speeds: float) -> list[Sample]:
    return [{'linear.x': v, 'angular.z': 0.0} for v in speeds]


def test_a_queue_of_the_last_level_is_skipped() -> None:
    before: Sample = {'linear.x': -0.6, 'angular.z': 0.0}
    samples = _cmds(*[-0.6] * 8, *[0.6] * _SAMPLES)
    assert _answered(samples, before) == 8
    assert _answered(samples[:8 + _SAMPLES - 1], before) is None  # not steady yet


def test_older_varying_input_is_not_an_answer() -> None:
    """A timer controller still working through the real sensor's sweep."""
    residual = _cmds(0.1, 0.2, 0.3, 0.4, 0.5, 0.55)
    answer = _cmds(*[-0.6] * _SAMPLES)
    assert _answered(residual + answer, {'linear.x': 0.3, 'angular.z': 0.0}) == len(residual)


def test_a_constant_controller_never_answers_a_change() -> None:
    assert _answered(_cmds(*[0.5] * 40), {'linear.x': 0.5, 'angular.z': 0.0}) is None


def test_the_first_level_takes_the_first_steady_run() -> None:
    assert _answered(_cmds(0.3, *[0.5] * _SAMPLES), None) == 1
    assert _answered([], None) is None


def test_a_word_command_answers_when_it_changes() -> None:
    slow: Sample = {'mode': 'SLOW'}
    fast: Sample = {'mode': 'FAST'}
    samples = [slow] * 3 + [fast] * 5
    assert _answered(samples, {'mode': 'SLOW'}) == 3


def test_the_table_shows_the_field_that_moved_first() -> None:
    levels: list[tuple[float, Sample, int]] = [
        (0.5, {'angular.x': 0.0, 'angular.y': 0.0, 'linear.x': -0.6}, 5),
        (2.5, {'angular.x': 0.0, 'angular.y': 0.0, 'linear.x': 0.6}, 5)]
    first = Response(True, levels=levels).table().splitlines()[0]
    assert first == '- input 0.5 → 5 command(s): linear.x = -0.6, angular.x = 0, angular.y = 0'


def test_a_sensor_of_booleans_is_driven_false_true_false() -> None:
    """A door contact publishing a Bool has no number to vary: its flag is driven."""
    keys, low, high = _varying([{'data': False}, {'data': False}])
    assert keys == {'data'}
    assert [_at_level({'data': False}, keys, level) for level in (low, high, low)] == [
        {'data': False}, {'data': True}, {'data': False}]
    numbers, low, high = _varying([{'range': 1.0, 'valid': True}, {'range': 2.0, 'valid': True}])
    assert numbers == {'range'}
    assert _at_level({'range': 1.0, 'valid': True}, numbers, high) == {'range': 2.0,
                                                                     'valid': True}
