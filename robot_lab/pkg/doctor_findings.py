"""What `robot-lab doctor` reports, and the package state its rules share.

A rule reads one part of a package (package.xml, setup.py, ...) and adds Findings, each
with the file, line and fix; the environment checklist is a list of Checks.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.xml_lines import XmlElement

__all__ = ['Check', 'Finding', 'PackageUnderCheck', 'Report', 'line_of']


@dataclass(frozen=True)
class Finding:
    """One problem in a package: where it is, what it is, and how to fix it."""

    severity: str  # 'error' or 'warning'
    message: str
    file: str | None = None
    line: int | None = None
    fix: str | None = None
    rule: str = ''

    def __str__(self) -> str:
        where = ''
        if self.file is not None:
            where = f'{self.file}:{self.line}: ' if self.line else f'{self.file}: '
        fix = f' (fix: {self.fix})' if self.fix else ''
        return f'{where}{self.severity}: {self.message}{fix}'


@dataclass(frozen=True)
class Check:
    """One line of the environment checklist."""

    name: str
    ok: bool
    detail: str
    fix: str | None = None
    severity: str = 'error'  # what a failed check counts as

    def __str__(self) -> str:
        mark = '[ok]' if self.ok else ('[!!]' if self.severity == 'error' else '[??]')
        fix = f' (fix: {self.fix})' if self.fix and not self.ok else ''
        return f'{mark} {self.name}: {self.detail}{fix}'


@dataclass
class Report:
    """Findings for a package (or the environment checklist); `.ok` when no errors."""

    path: Path | None
    findings: list[Finding] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)

    @property
    def errors(self) -> list[Finding]:
        return [f for f in self.findings if f.severity == 'error']

    @property
    def warnings(self) -> list[Finding]:
        return [f for f in self.findings if f.severity == 'warning']

    @property
    def ok(self) -> bool:
        failed = [c for c in self.checks if not c.ok and c.severity == 'error']
        return not self.errors and not failed

    def rules(self) -> set[str]:
        return {f.rule for f in self.findings}

    def summary(self) -> str:
        if self.path is None:
            bad = sum(1 for c in self.checks if not c.ok)
            return 'environment OK' if bad == 0 else f'{bad} check(s) need attention'
        if not self.findings:
            return f'{self.path}: no problems found'
        return f'{self.path}: {len(self.errors)} error(s), {len(self.warnings)} warning(s)'

    def __str__(self) -> str:
        lines = [str(c) for c in self.checks] + [str(f) for f in self.findings]
        return '\n'.join([*lines, self.summary()])

    def _repr_html_(self) -> str:
        colours = {'error': '#cf222e', 'warning': '#9a6700'}
        rows = []
        for check in self.checks:
            colour = '#1a7f37' if check.ok else colours[check.severity]
            rows.append(f'<li style="color:{colour}">{html.escape(str(check))}</li>')
        for finding in self.findings:
            colour = colours.get(finding.severity, '#000')
            rows.append(f'<li style="color:{colour}"><code>{html.escape(str(finding))}</code></li>')
        head = html.escape(self.summary())
        return f'<div><b>{head}</b><ul>{"".join(rows)}</ul></div>'


# --- the package under check ---------------------------------------------------


@dataclass
class PackageUnderCheck:
    """What the rules share: the package folder and what package.xml declares."""

    dir: Path
    name: str
    xml: XmlElement | None = None
    declared: set[str] = field(default_factory=set)  # depend + exec_depend
    findings: list[Finding] = field(default_factory=list)

    def rel(self, *parts: str) -> str:
        return str(self.dir.joinpath(*parts))

    def add(self, rule: str, severity: str, message: str, file: str | None,
            line: int | None = None, fix: str | None = None) -> None:
        self.findings.append(Finding(severity, message, file, line, fix, rule))


def line_of(text: str, needle: str) -> int | None:
    for number, line in enumerate(text.splitlines(), 1):
        if needle in line:
            return number
    return None
