"""`readme`: the package explains how to build it and how to start it."""

from __future__ import annotations

import re
from pathlib import Path

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['readme', 'readme_verdict']


def readme_verdict(package: Path, require: list[str], launch_files: list[Path]) -> Verdict:
    """A README that says how to build the package and which launch file to start."""
    readmes = sorted(p for p in package.iterdir()
                     if p.is_file() and p.name.lower().startswith('readme'))
    if not readmes:
        return Verdict(False, 'a README (README.md) in the package folder with usage instructions',
                       'no README file in ' + package.name + '/',
                       'add README.md saying how to build (`colcon build`), source '
                       '(`source install/setup.bash`) and launch '
                       '(`ros2 launch <package> <launch file>`) your system')
    text = readmes[0].read_text(errors='replace')[:100_000].lower()
    names = [p.name.lower() for p in launch_files]
    # Usage in prose counts: how to build (colcon) and which launch file starts the system.
    said = {'build': bool(re.search(r'\bcolcon\b|robot-lab\s+build', text)),
            'launch': bool(re.search(r'ros2\s+launch|robot-lab\s+launch', text))
            or any(name in text for name in names)}
    exact = bool(re.search(r'colcon\s+build|robot-lab\s+build', text)
                 and re.search(r'ros2\s+launch|robot-lab\s+launch', text))
    missing = [what for what in require if not said.get(what, re.escape(what) in text)]
    suggestion = (f'`colcon build --packages-select {package.name}`, then `source '
                  f'install/setup.bash` and `ros2 launch {package.name} '
                  f'{launch_files[0].name if launch_files else "<launch file>"}`')
    if missing:
        what = {'build': 'how to build it (colcon)',
                'launch': 'which launch file starts the system'}
        return Verdict(False, 'the README says how to build the package and which launch file '
                       'to start', f'{readmes[0].name} does not say '
                       + ' or '.join(what.get(m, m) for m in missing),
                       f'add the usage as a user types it, e.g. {suggestion}')
    observed = f'{readmes[0].name} says how to build and which launch file to start'
    if not exact:
        observed += f' (a suggestion: give the exact commands, {suggestion})'
    return Verdict(True, 'a README with build and launch instructions', observed)


@register('readme', stage='files')
def readme(state: JobState, check: RubricCheck) -> Verdict:
    assert state.package is not None
    return readme_verdict(state.package, list(check.option('require', ['build', 'launch'])),
                          state.launch_files)
