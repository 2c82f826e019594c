"""`readme`: the package explains how to build it and how to start it."""

from __future__ import annotations

import re
from pathlib import Path

from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['readme', 'readme_verdict']


def readme_verdict(package: Path, require: list[str]) -> Verdict:
    """A README that names the build and the launch command."""
    readmes = sorted(p for p in package.iterdir()
                     if p.is_file() and p.name.lower().startswith('readme'))
    if not readmes:
        return Verdict(False, 'a README (README.md) in the package folder with usage instructions',
                       'no README file in ' + package.name + '/',
                       'add README.md saying how to build (`colcon build`), source '
                       '(`source install/setup.bash`) and launch '
                       '(`ros2 launch <package> <launch file>`) your system')
    text = readmes[0].read_text(errors='replace')[:100_000].lower()
    patterns = {'build': r'colcon\s+build|robot-lab\s+build',
                'launch': r'ros2\s+launch|robot-lab\s+launch'}
    missing = [what for what in require if not re.search(patterns.get(what, re.escape(what)), text)]
    if missing:
        names = {'build': '`colcon build`', 'launch': '`ros2 launch ...`'}
        return Verdict(False, 'the README gives the build and the launch command',
                       f'{readmes[0].name} does not mention: '
                       + ', '.join(names.get(m, m) for m in missing),
                       'add the commands as a user types them, e.g. `colcon build '
                       '--packages-select <pkg>` and `ros2 launch <pkg> <file>`')
    return Verdict(True, 'a README with build and launch instructions',
                   f'{readmes[0].name} gives both')


@register('readme', stage='files')
def readme(state: JobState, check: RubricCheck) -> Verdict:
    assert state.package is not None
    return readme_verdict(state.package, list(check.option('require', ['build', 'launch'])))
