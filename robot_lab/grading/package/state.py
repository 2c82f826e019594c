"""What one package job found, stage by stage: the state every check reads.

`job` fills the files and the build, `live` the running system (`LiveRun`); the checks
(`checks/`) only read it and return a `Verdict`, which `job` turns into the student's
`CheckOutcome` with the rubric's points. Parameter files are parsed once per job
(`JobState.params`), whichever stage asks first.

A failure of the grader's own calls (a ROS query, a parameter read, the perturbation, a
file read, a stage that raised) is never the student's loss: it is kept as the `fault` it
is (`LiveRun.grader_fault`, `ParamReading.error`, `JobState.stage_faults`), and a check it
may have changed returns a `Verdict` with `grader_error` set, which `job` scores as a
grader error: the points kept, the check marked for a regrade.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import ParamFileError
from robot_lab.grading.package.rubric import Rubric
from robot_lab.grading.report import CheckOutcome

if TYPE_CHECKING:
    from robot_lab.grading.package.crash import Crash
    from robot_lab.grading.package.perturb import Response
    from robot_lab.grading.package.roles import Observation, Roles
    from robot_lab.grading.package.tf_watch import TfEdge
    from robot_lab.launch.api import ProcessStatus

__all__ = ['LINES', 'JobState', 'LiveRun', 'ParamReading', 'Verdict', 'code', 'section']

LINES = 12  # log / build lines shown per check


def section(expected: str, observed: str, fix: str = '') -> str:
    """A check's feedback: what was expected, what was observed, how to fix it."""
    text = f'**Expected:** {expected}\n\n**Observed:** {observed}'
    if fix:
        text += f'\n\n**How to fix:** {fix}'
    return text


def code(lines: list[str] | str, limit: int = LINES) -> str:
    """The last `limit` lines as a Markdown code block."""
    items = lines.splitlines() if isinstance(lines, str) else list(lines)
    if len(items) > limit:
        items = [f'... ({len(items) - limit} earlier lines cut)', *items[-limit:]]
    body = '\n'.join(line[:300] for line in items).replace('```', "'''")
    return f'\n\n```\n{body}\n```\n'


@dataclass
class Verdict:
    """A check's result before the rubric weighs it: `earned` True/False or a fraction."""

    earned: bool | float
    expected: str
    observed: str
    fix: str = ''
    grader_error: str = ''  # the grader's own failure that may have decided this verdict

    @property
    def fraction(self) -> float:
        return float(self.earned)

    def text(self) -> str:
        return section(self.expected, self.observed, '' if self.fraction >= 1 else self.fix)


@dataclass
class ParamReading:
    """One parameter of the student's file, read back from the running nodes."""

    pattern: str  # the file's node key ('/**', 'range_sensor')
    name: str
    file_value: Any
    node: str | None  # the node that holds it, None when none does
    held: Any = None
    error: str = ''  # the grader could not read it from `node` (a timeout): not the student's


@dataclass
class LiveRun:
    """The student's system as launched and observed (robot_lab.grading.package.live).

    `not_run` says why nothing ran (the build failed, no launch file and no executables,
    the launcher refused); the run checks then fail with that reason and `fix`.
    """

    not_run: str = ''
    fix: str = ''
    launch_name: str = ''  # the launch file run ('' when the grader started the executables)
    notes: list[str] = field(default_factory=list)
    dropped: list[str] = field(default_factory=list)  # parameter files rcl would refuse
    statuses: list[ProcessStatus] = field(default_factory=list)
    logs: dict[str, str] = field(default_factory=dict)  # label -> last output (Markdown)
    line_rates: dict[str, float] = field(default_factory=dict)  # node -> lines/s written
    obs: Observation | None = None
    roles: Roles | None = None
    params_loaded: dict[str, list[str]] = field(default_factory=dict)  # file -> nodes
    readings: list[ParamReading] = field(default_factory=list)
    alive_nodes: set[str] = field(default_factory=set)  # in the graph when the watch ended
    crashes: dict[str, Crash] = field(default_factory=dict)  # label -> why it died
    response: Response | None = None  # the controller driven by the grader (perturb)
    grader_fault: str = ''  # the grader's own failure that kept the system from being watched
    tf_edges: set[TfEdge] | None = None  # heard by a tf2 listener (the `tf_tree` check)

    def not_run_verdict(self, expected: str) -> Verdict:
        return Verdict(False, expected, self.not_run, self.fix, grader_error=self.grader_fault)

    def watched(self) -> tuple[Observation, Roles] | None:
        """What the observer saw and the roles in it; None when nothing ran."""
        if self.not_run or self.obs is None or self.roles is None:
            return None
        return self.obs, self.roles

    def died(self) -> list[ProcessStatus]:
        return [p for p in self.statuses if p.state == 'died' or p.exit_code not in (None, 0)]

    def dead(self) -> str:
        """The processes that died: why, in the student's own source (else the last output)."""
        text = ''
        for p in self.died():
            crash = self.crashes.get(p.label)
            if crash is None:
                text += (f'\n\n`{p.label}` exited with code {p.exit_code}; its last output:'
                         f'{self.logs.get(p.label, "")}')
            else:
                text += f'\n\n`{p.label}` exited with code {p.exit_code}: {crash.markdown()}'
        return text

    def crash_fix(self) -> str:
        """The fix for the first crash, when a node died (it, not the wiring, is the cause)."""
        for p in self.died():
            crash = self.crashes.get(p.label)
            if crash is not None and crash.fix:
                return f'first fix the crash of `{p.label}`: {crash.fix}'
        return ''

    def seen(self) -> str:
        """The topics the observer saw (who publishes, who subscribes), then the dead."""
        topics = self.obs.topics.values() if self.obs else []
        rows = [f'- `{t.name}` [{", ".join(t.types)}] {t.count} msgs ({t.rate:.1f} Hz); '
                f'published by {", ".join(t.publishers) or "-"}, '
                f'subscribed by {", ".join(t.subscribers) or "-"}'
                for t in sorted(topics, key=lambda t: t.name)][:12]
        return 'topics seen:\n\n' + ('\n'.join(rows) if rows else '(none)') + self.dead()


@dataclass
class JobState:
    """What the stages found; the checks read it."""

    rubric: Rubric
    package: Path | None = None
    package_name: str = ''
    launch_files: list[Path] = field(default_factory=list)
    param_files: list[Path] = field(default_factory=list)
    built: bool | None = None
    build_lines: list[str] = field(default_factory=list)
    build_note: str = ''  # what the build finished ('built pkg in 3.1 s')
    live: LiveRun = field(default_factory=LiveRun)
    outcomes: dict[str, CheckOutcome] = field(default_factory=dict)
    images: list[Path] = field(default_factory=list)
    grader_errors: list[str] = field(default_factory=list)
    # check id -> a failure of the grader's that may have decided it (e.g. the watch's
    # graph queries): a failing verdict of that check is a grader error
    check_faults: dict[str, str] = field(default_factory=dict)
    # stage -> the grader's failure in it (a stage that raised): later checks may lack data
    stage_faults: dict[str, str] = field(default_factory=dict)
    started: float = field(default_factory=time.monotonic)
    blocked: list[str] = field(default_factory=list)  # what the sandbox refused, for feedback
    _parsed: dict[str, dict[str, dict[str, Any]] | ParamFileError] = field(
        default_factory=dict, repr=False)
    # checks/description: the robot description (file wanted -> the robot and its path, or
    # the student's error), read once per job: a .xacro is expanded by one xacro run
    descriptions: dict[str, Any] = field(default_factory=dict, repr=False)

    def time_left(self) -> float:
        """Seconds of the job's wall-clock budget (the rubric's limits) not used yet."""
        return self.rubric.limits.wall_seconds - (time.monotonic() - self.started)

    def option(self, check_id: str, key: str, default: Any) -> Any:
        """A rubric option of a check (its default when the rubric drops the check)."""
        check = self.rubric.check(check_id)
        return check.option(key, default) if check else default

    def params(self, path: str | Path) -> dict[str, dict[str, Any]]:
        """A parameter file under rcl's rules (robot_lab.params), parsed once per content:
        the source file and its installed copy are one parse; ParamFileError as rcl's."""
        from robot_lab.params import load_param_file

        file = Path(path)
        try:
            digest = hashlib.sha256(file.read_bytes()).hexdigest() + '/' + file.name
        except OSError:
            return load_param_file(file)  # raises the reader's ParamFileError
        if digest not in self._parsed:
            try:
                self._parsed[digest] = load_param_file(file)
            except ParamFileError as err:
                self._parsed[digest] = err
        found = self._parsed[digest]
        if isinstance(found, ParamFileError):
            raise found
        return found
