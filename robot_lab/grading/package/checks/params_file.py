"""`params_file`: a parameter file rcl accepts, with enough parameters."""

from __future__ import annotations

from robot_lab.errors import ParamFileError
from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['params_file']


@register('params_file', stage='files')
def params_file(state: JobState, check: RubricCheck) -> Verdict:
    minimum = int(check.option('min_parameters', 3))
    assert state.package is not None
    if not state.param_files:
        return Verdict(
            False, f'a parameter file (e.g. config/params.yaml) with at least {minimum} '
            'parameters', 'no .yaml file in the package besides launch files',
            'add config/params.yaml in the ros__parameters layout '
            '(`node_name:` / `  ros__parameters:` / `    name: value`) and install it '
            "with data_files in setup.py: ('share/' + package_name + '/config', "
            "glob('config/*.yaml'))")
    notes, best = [], 0
    for path in state.param_files:
        rel = path.relative_to(state.package)
        try:
            count = sum(len(params) for params in state.params(path).values())
        except ParamFileError as err:
            notes.append(f'{rel}: {err}')
            continue
        notes.append(f'{rel}: {count} parameter(s)')
        best = max(best, count)
    passed = best >= minimum
    fix = ('rcl accepts only `node_name:` / `  ros__parameters:` / `    name: value`; '
           'fix the line named above' if best == 0 and any(':' in n and 'parameter(s)' not in n
                                                           for n in notes)
           else f'give the nodes at least {minimum} parameters in the file')
    return Verdict(passed, f'a parameter file valid under rcl rules with at least {minimum} '
                   'parameters',
                   '\n\n'.join(f'`{n}`' if 'parameter(s)' in n else n for n in notes), fix)
