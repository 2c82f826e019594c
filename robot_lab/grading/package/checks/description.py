"""`urdf_describes` and `tf_tree`: a robot description in the package (Chapter 7).

`urdf_describes` (files): the package's URDF (or .urdf.xacro, expanded by xacro with
`$(find pkg)` resolved to the workspace's packages) parses as check_urdf parses it, and has
the links, root, parents and joint types the rubric names (in any order).
`tf_tree` (run): the running system publishes that tree: robot_state_publisher's
`/robot_description`, and, heard by a tf2 listener (robot_lab.grading.package.tf_watch) on
`/tf` and `/tf_static`, every joint's parent → child with one parent per frame, up to the
rubric's root frame. Without the listener's edges (a grader that did not record them) the
moving joints are read from what the watch saw on `/tf`.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from robot_lab.errors import UrdfError
from robot_lab.grading.package.registry import register
from robot_lab.grading.package.rubric import RubricCheck
from robot_lab.grading.package.state import JobState, Verdict
from robot_lab.grading.package.tf_watch import TfEdge

__all__ = ['NoDescriptionError', 'description_files', 'read_description', 'tf_tree',
           'urdf_describes']

_SKIP = {'build', 'install', 'log', '.git', '__pycache__'}
_FOLDERS = ('urdf', 'description')  # where a description package keeps its model
_KINDS = ('.urdf', '.urdf.xacro', '.xacro')  # plain URDF first; a bare .xacro is often a macro


class NoDescriptionError(LookupError):
    """The package holds no .urdf or .xacro file (the student's omission, not an OSError)."""


def description_files(package: Path, wanted: str | None = None) -> list[Path]:
    """The package's robot descriptions, best first (`wanted`: one path in the package)."""
    if wanted:
        return [package / wanted] if (package / wanted).is_file() else []
    found = [p for p in package.rglob('*') if p.is_file() and p.name.endswith(_KINDS)
             and not _SKIP & set(p.relative_to(package).parts)]

    def rank(p: Path) -> tuple[bool, int, int, str]:
        rel = p.relative_to(package).parts
        kind = next(i for i, k in enumerate(_KINDS) if p.name.endswith(k))
        return rel[0] not in _FOLDERS, kind, len(rel), str(p)

    return sorted(found, key=rank)


def _package_name(folder: Path) -> str | None:
    try:
        text = (folder / 'package.xml').read_text(errors='replace')
    except OSError:
        return None
    match = re.search(r'<name>\s*([^<\s]+)\s*</name>', text)
    return match.group(1) if match else None


def _source_prefix(state: JobState, prefix: Path) -> str:
    """An ament prefix in `prefix` whose share/<pkg> is each package of the job's workspace
    (its source, so before the build too), for xacro's `$(find pkg)`; AMENT_PREFIX_PATH."""
    assert state.package is not None
    packages = {state.package_name or state.package.name: state.package}
    for sibling in sorted(state.package.parent.iterdir()):
        name = _package_name(sibling) if sibling.is_dir() else None
        if name and name not in packages:
            packages[name] = sibling
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    for name, folder in packages.items():
        (index / name).touch()
        (prefix / 'share' / name).symlink_to(folder.resolve(), target_is_directory=True)
    return os.pathsep.join(p for p in (str(prefix), os.environ.get('AMENT_PREFIX_PATH', ''))
                           if p)


def _xacro(path: Path, state: JobState) -> str:
    """The URDF `xacro` makes of `path` (the venv's xacro, as a launch file's Command runs it),
    with `$(find pkg)` finding the packages of the job's workspace."""
    program = shutil.which('xacro') or str(Path(sys.executable).with_name('xacro'))
    with tempfile.TemporaryDirectory(prefix='robot_lab_xacro_') as prefix:
        env = dict(os.environ, AMENT_PREFIX_PATH=_source_prefix(state, Path(prefix)))
        done = subprocess.run([program, str(path)], capture_output=True, text=True,
                              timeout=60, check=False, env=env, cwd=path.parent)
    if done.returncode != 0:
        first = (done.stderr.strip().splitlines() or ['no message'])[0]
        raise UrdfError(f'xacro failed: {first.removeprefix("error: ")}', file=path.name,
                        fix=f'run `xacro {path.name}` and fix what it names')
    return done.stdout


def read_description(state: JobState, wanted: str | None) -> tuple[Any, str]:
    """(the parsed robot, its path in the package); UrdfError when there is none or it is
    refused, NoDescriptionError when the package has none; OSError and TimeoutExpired are the
    grader's (its copy unreadable, its xacro missing or starved).

    Read once per job (`urdf_describes` at the files stage, `tf_tree` at the run stage ask
    for the same file): xacro runs once. The grader's own failures are not kept, so a later
    stage tries again."""
    key = wanted or ''
    if key not in state.descriptions:
        try:
            state.descriptions[key] = _read_description(state, wanted)
        except (NoDescriptionError, UrdfError) as err:
            state.descriptions[key] = err
    found = state.descriptions[key]
    if isinstance(found, (NoDescriptionError, UrdfError)):
        raise found
    robot, rel = found
    return robot, str(rel)


def _read_description(state: JobState, wanted: str | None) -> tuple[Any, str]:
    from robot_lab.urdf.model import parse_urdf

    assert state.package is not None
    files = description_files(state.package, wanted)
    if not files:
        raise NoDescriptionError(wanted or 'urdf/*.urdf')
    path = files[0]
    rel = str(path.relative_to(state.package))
    if not path.name.endswith('.xacro'):
        return parse_urdf(path.read_text(errors='replace'), rel), rel
    try:
        return parse_urdf(_xacro(path, state), rel), rel
    except UrdfError as err:
        if err.line is None or err.message.startswith('xacro failed'):
            raise
        raise _in_source(err, state.package, rel) from err


def _source_line(package: Path, name: str) -> tuple[str, int] | None:
    """(file, line) of the one line of the package's descriptions with `name="NAME"`."""
    hits = []
    for path in description_files(package):
        lines = path.read_text(errors='replace').splitlines()
        hits += [(str(path.relative_to(package)), i) for i, text in enumerate(lines, 1)
                 if f'name="{name}"' in text]
    return hits[0] if len(hits) == 1 else None


def _in_source(err: UrdfError, package: Path, rel: str) -> UrdfError:
    """A refusal of xacro's output placed in the student's files: the line that names the
    element (`name="left_wheel_joint"`), else the line of xacro's output, said so."""
    for name in re.findall(r"'([^']+)'", err.message)[:1]:
        if (found := _source_line(package, name)) is not None:
            return UrdfError(err.message, file=found[0], line=found[1], fix=err.fix)
    return UrdfError(f"line {err.line} of xacro's output: {err.message}", file=rel,
                     fix=err.fix)


def _where(joint: Any, rel: str, package: Path) -> str:
    """Where the student wrote a joint: its line, in a xacro its file:line when one line
    names it, else the macro that made it."""
    if not rel.endswith('.xacro'):
        return f'line {joint.line}'
    found = _source_line(package, joint.name)
    return f'{found[0]}:{found[1]}' if found else 'made by a xacro macro'


def _differences(robot: Any, links: list[str], parents: dict[str, str],
                 joints: dict[str, str], root: str, where: Callable[[Any], str]) -> list[str]:
    from robot_lab.urdf.compare import differences

    wrong = []
    for found in differences(robot, links=links, parents=parents, joint_types=joints,
                             root=root):
        name, wanted, joint = found.name, found.wanted, found.joint
        if found.kind == 'no_link':
            wrong.append(f'no link `{name}`')
        elif found.kind == 'root':
            wrong.append(f'the root link is `{name}`, not `{wanted}` (every other link hangs '
                         f'from `{wanted}` through joints)')
        elif found.kind == 'parent':
            has = 'no parent (it is the root)' if joint is None else \
                f'parent `{joint.parent}` (joint `{joint.name}`, {where(joint)})'
            wrong.append(f'`{name}` has {has}, not `{wanted}`')
        elif found.kind == 'no_joint':
            wrong.append(f'no joint `{name}`')
        elif joint is not None:  # joint_type
            wrong.append(f'joint `{name}` is {joint.type}, not {wanted} ({where(joint)})')
    return wrong


@register('urdf_describes', stage='files')
def urdf_describes(state: JobState, check: RubricCheck) -> Verdict:
    links = [str(n) for n in check.option('links', [])]
    parents = {str(k): str(v) for k, v in dict(check.option('parents', {})).items()}
    joints = {str(k): str(v) for k, v in dict(check.option('joints', {})).items()}
    root = str(check.option('root', '') or '')
    expected = 'a robot description (urdf/*.urdf or .urdf.xacro) that check_urdf accepts' + (
        f', with the links {", ".join(links)}' if links else '') + (
        f', rooted at `{root}`' if root else '')
    try:
        robot, rel = read_description(state, check.option('file', None))
    except NoDescriptionError:
        return Verdict(False, expected, f'no .urdf or .xacro file in `{state.package_name}/`',
                       'put the model in urdf/ (e.g. urdf/my_robot.urdf) and install it with '
                       "setup.py's data_files: ('share/' + package_name + '/urdf', "
                       "glob('urdf/*'))")
    except UrdfError as err:
        return Verdict(False, expected, f'check_urdf refuses it: {err}', err.fix or
                       'run `check_urdf` on the file and fix the line it names')
    except (OSError, subprocess.TimeoutExpired) as err:  # the grader's own calls
        return Verdict(False, expected, 'the grader could not read or expand the description',
                       grader_error=f'{type(err).__name__}: {err}')
    wrong = _differences(robot, links, parents, joints, root,
                         lambda joint: _where(joint, rel, state.package or Path()))
    summary = (f'`{rel}`: robot `{robot.name}`, root `{robot.root}`, {len(robot.links)} links, '
               f'{len(robot.joints)} joints')
    if wrong:
        return Verdict(False, expected, f'{summary}; but ' + '; '.join(wrong),
                       'each joint names its parent (what the part is fixed to) and its child; '
                       'a wheel is continuous, a bolted part fixed')
    return Verdict(True, expected, summary)


def _shape(robot: Any, edges: set[TfEdge], prefix: str, root: str) -> list[str]:
    """How the TF tree a tf2 listener heard differs from the model's: a frame missing, on
    another parent, with two parents, or a tree whose root is not `root`."""
    parents: dict[str, set[str]] = {}
    for edge in edges:
        parents.setdefault(edge.child, set()).add(edge.parent)
    wrong: list[str] = []
    for joint in robot.joints.values():
        if joint.type == 'floating':  # robot_state_publisher skips them, as KDL does
            continue
        child, parent = prefix + joint.child, prefix + joint.parent
        heard = parents.get(child, set())
        if not heard:
            why = ('' if not joint.moves else ' (a moving joint is published only when '
                   '/joint_states gives its position: is joint_state_publisher running?)')
            wrong.append(f'no transform {parent} → {child} (joint `{joint.name}`){why}')
        elif heard != {parent}:
            wrong.append(f'`{child}` has the parent(s) {", ".join(sorted(heard))} in the '
                         f'TF tree, not `{parent}` as joint `{joint.name}` says')
    for child, heard in sorted(parents.items()):
        if len(heard) > 1 and child.removeprefix(prefix) not in robot.links:
            wrong.append(f'`{child}` has two parents in the TF tree: {", ".join(sorted(heard))}')
    top, seen = prefix + robot.root, set()
    while top in parents and len(parents[top]) == 1 and top not in seen:
        seen.add(top)
        top = next(iter(parents[top]))
    if root and top != root and (prefix + robot.root) in {e.parent for e in edges}:
        wrong.append(f"the TF tree's root is `{top}`, not `{root}`")
    return wrong


def _tf_moving(robot: Any, obs: Any, prefix: str) -> list[str]:
    """The moving joints never seen on /tf by the watch (no tf2 listener's edges)."""
    moving = {(prefix + j.parent, prefix + j.child) for j in robot.joints.values() if j.moves}
    edges: set[tuple[str, str]] = set()
    tf = obs.topics.get('/tf')
    for value in tf.values if tf is not None else []:
        for t in value.get('transforms', []):
            edges.add((str(t.get('header', {}).get('frame_id', '')).lstrip('/'),
                       str(t.get('child_frame_id', '')).lstrip('/')))
    unseen = sorted(moving - edges)
    wrong = ['/tf never carried ' + ', '.join(f'{p} → {c}' for p, c in unseen)
             + ' (joint_state_publisher gives robot_state_publisher the angles)'] if unseen else []
    static = obs.topics.get('/tf_static')
    if any(j.type == 'fixed' for j in robot.joints.values()) and (
            static is None or not static.publishers):
        wrong.append('nobody publishes /tf_static for the fixed joints')
    return wrong


@register('tf_tree', stage='run')
def tf_tree(state: JobState, check: RubricCheck) -> Verdict:
    root = str(check.option('root', '') or '')
    expected = ('the running system publishes the description: /robot_description, and a '
                'TF tree (/tf, /tf_static) with every joint of the URDF as parent → child'
                + (f', rooted at `{root}`' if root else ''))
    live = state.live
    if (watched := live.watched()) is None:
        return live.not_run_verdict(expected)
    obs, _roles = watched
    try:
        robot, rel = read_description(state, check.option('file', None))
    except (NoDescriptionError, UrdfError):
        return Verdict(False, expected, 'no robot description the grader can read (see the '
                       'URDF check)', 'fix the URDF first')
    except (OSError, subprocess.TimeoutExpired) as err:  # the grader's own calls
        return Verdict(False, expected, 'the grader could not read or expand the description',
                       grader_error=f'{type(err).__name__}: {err}')
    prefix = str(check.option('frame_prefix', ''))
    missing: list[str] = []
    description = obs.topics.get('/robot_description')
    if description is None or not description.publishers:
        missing.append('nobody publishes /robot_description (is robot_state_publisher in '
                       'your launch file?)')
    edges = live.tf_edges
    missing += (_tf_moving(robot, obs, prefix) if edges is None
                else _shape(robot, edges, prefix, root))
    counts = f'`{rel}` has {len(robot.joints)} joints ({len(robot.movable_joints())} moving)'
    if missing:
        return Verdict(False, expected, f'{counts}; ' + '; '.join(missing) + live.dead(),
                       live.crash_fix() or
                       'launch robot_state_publisher with robot_description set to the '
                       "model's text (xacro's output), and joint_state_publisher beside it")
    heard = (f'the TF tree heard: {len(edges)} edges' if edges is not None else
             f'/tf carries {len(robot.movable_joints())} moving joint(s); /tf_static published')
    return Verdict(True, expected, f'{counts}; /robot_description published; {heard}')
