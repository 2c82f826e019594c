"""`urdf_describes` and `tf_tree`: a robot description in the package (Chapter 7).

`urdf_describes` (files): the package's URDF (or .urdf.xacro, expanded by xacro) parses as
check_urdf parses it, and has the links, parents and joint types the rubric names.
`tf_tree` (run): the running system publishes that tree: robot_state_publisher's
`/robot_description`, each moving joint's parent → child on `/tf`, `/tf_static` for the
fixed ones (its transient-local message itself is sent once, before the watch subscribes,
so the watch sees its publisher, not its content).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

from robot_lab.errors import UrdfError
from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict

__all__ = ['description_files', 'read_description', 'tf_tree', 'urdf_describes']

_SKIP = {'build', 'install', 'log', '.git', '__pycache__'}


def description_files(package: Path, wanted: str | None = None) -> list[Path]:
    """The package's robot descriptions (`wanted`: one path relative to the package)."""
    if wanted:
        return [package / wanted] if (package / wanted).is_file() else []
    found = [p for p in package.rglob('*') if p.is_file()
             and p.name.endswith(('.urdf', '.urdf.xacro', '.xacro'))
             and not _SKIP & set(p.relative_to(package).parts)]
    # Plain URDF first (what check_urdf reads), then xacro; shallowest first.
    return sorted(found, key=lambda p: (p.name.endswith('.xacro'), len(p.parts), str(p)))


def _xacro(path: Path) -> str:
    """The URDF `xacro` makes of `path` (the venv's xacro, as a launch file's Command runs it)."""
    program = shutil.which('xacro') or str(Path(sys.executable).with_name('xacro'))
    done = subprocess.run([program, str(path)], capture_output=True, text=True, timeout=60,
                          check=False)
    if done.returncode != 0:
        first = (done.stderr.strip().splitlines() or ['no message'])[0]
        raise UrdfError(f'xacro failed: {first.removeprefix("error: ")}', file=path.name,
                        fix=f'run `xacro {path.name}` and fix what it names')
    return done.stdout


def read_description(state: JobState, wanted: str | None) -> tuple[Any, str]:
    """(the parsed robot, its path in the package); UrdfError when there is none or it is
    refused, FileNotFoundError when the package has no description at all."""
    from robot_lab.urdf.model import parse_urdf

    assert state.package is not None
    files = description_files(state.package, wanted)
    if not files:
        raise FileNotFoundError(wanted or 'urdf/*.urdf')
    path = files[0]
    rel = str(path.relative_to(state.package))
    text = _xacro(path) if path.name.endswith('.xacro') else path.read_text(errors='replace')
    return parse_urdf(text, rel), rel


def _differences(robot: Any, links: list[str], parents: dict[str, str],
                 joints: dict[str, str]) -> list[str]:
    wrong = [f'no link `{name}`' for name in links if name not in robot.links]
    for child, parent in parents.items():
        joint = robot.parent_joint(child)
        if child in robot.links and (joint is None or joint.parent != parent):
            has = 'no parent (it is the root)' if joint is None else \
                f'parent `{joint.parent}` (joint `{joint.name}`, line {joint.line})'
            wrong.append(f'`{child}` has {has}, not `{parent}`')
    for name, kind in joints.items():
        joint = robot.joints.get(name)
        if joint is None:
            wrong.append(f'no joint `{name}`')
        elif joint.type != kind:
            wrong.append(f'joint `{name}` is {joint.type}, not {kind} (line {joint.line})')
    return wrong


@register('urdf_describes', stage='files')
def urdf_describes(state: JobState, check: RubricCheck) -> Verdict:
    links = [str(n) for n in check.option('links', [])]
    parents = {str(k): str(v) for k, v in dict(check.option('parents', {})).items()}
    joints = {str(k): str(v) for k, v in dict(check.option('joints', {})).items()}
    expected = 'a robot description (urdf/*.urdf or .urdf.xacro) that check_urdf accepts' + (
        f', with the links {", ".join(links)}' if links else '')
    try:
        robot, rel = read_description(state, check.option('file', None))
    except FileNotFoundError:
        return Verdict(False, expected, f'no .urdf or .xacro file in `{state.package_name}/`',
                       'put the model in urdf/ (e.g. urdf/my_robot.urdf) and install it with '
                       "setup.py's data_files: ('share/' + package_name + '/urdf', "
                       "glob('urdf/*'))")
    except UrdfError as err:
        return Verdict(False, expected, f'check_urdf refuses it: {err}', err.fix or
                       'run `check_urdf` on the file and fix the line it names')
    except (OSError, subprocess.TimeoutExpired) as err:
        return Verdict(False, expected, f'the description could not be read: {err}',
                       'make it a readable text file that xacro expands in seconds')
    wrong = _differences(robot, links, parents, joints)
    summary = (f'`{rel}`: robot `{robot.name}`, root `{robot.root}`, {len(robot.links)} links, '
               f'{len(robot.joints)} joints')
    if wrong:
        return Verdict(False, expected, f'{summary}; but ' + '; '.join(wrong),
                       'each joint names its parent (what the part is fixed to) and its child; '
                       'a wheel is continuous, a bolted part fixed')
    return Verdict(True, expected, summary)


@register('tf_tree', stage='run')
def tf_tree(state: JobState, check: RubricCheck) -> Verdict:
    expected = ('the running system publishes the description: /robot_description, each '
                'moving joint on /tf, the fixed ones on /tf_static')
    live = state.live
    if (watched := live.watched()) is None:
        return live.not_run_verdict(expected)
    obs, _roles = watched
    try:
        robot, rel = read_description(state, check.option('file', None))
    except (FileNotFoundError, UrdfError, OSError, subprocess.TimeoutExpired):
        return Verdict(False, expected, 'no robot description the grader can read (see the '
                       'URDF check)', 'fix the URDF first')
    prefix = str(check.option('frame_prefix', ''))
    moving = {(prefix + j.parent, prefix + j.child) for j in robot.joints.values() if j.moves}
    fixed = [j for j in robot.joints.values() if j.type == 'fixed']
    missing: list[str] = []
    description = obs.topics.get('/robot_description')
    if description is None or not description.publishers:
        missing.append('nobody publishes /robot_description (is robot_state_publisher in '
                       'your launch file?)')
    edges: set[tuple[str, str]] = set()
    tf = obs.topics.get('/tf')
    for value in tf.values if tf is not None else []:
        for t in value.get('transforms', []):
            edges.add((str(t.get('header', {}).get('frame_id', '')).lstrip('/'),
                       str(t.get('child_frame_id', '')).lstrip('/')))
    unseen = sorted(moving - edges)
    if unseen:
        missing.append('/tf never carried ' + ', '.join(f'{p} → {c}' for p, c in unseen)
                       + ' (joint_state_publisher gives robot_state_publisher the angles)')
    static = obs.topics.get('/tf_static')
    if fixed and (static is None or not static.publishers):
        missing.append('nobody publishes /tf_static for the fixed joints')
    if missing:
        return Verdict(False, expected, f'`{rel}` has {len(moving)} moving and {len(fixed)} '
                       'fixed joints; ' + '; '.join(missing) + live.dead(),
                       'launch robot_state_publisher with robot_description set to the '
                       "model's text, and joint_state_publisher beside it")
    return Verdict(True, expected, f'/robot_description published; /tf carries '
                   f'{len(moving)} moving joint(s) of `{rel}`; /tf_static published')
