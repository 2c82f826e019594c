"""What a grader hands back to an instructor: a gradebook, feedback, Gradescope results.

One data model for every kind of submission (packages, notebooks): a `StudentReport` holds
one `CheckOutcome` per rubric check, and `write_outputs(out_dir, reports)` writes

- `OUT/grades.csv` — `student,score,max_score,<check ids>`, a cell is the points earned;
- `OUT/feedback/<student>.md` and `.html` — per check: points, then the check's output
  (what was expected, what was observed, how to fix it), and any pictures (both carry them
  as data URIs, so a page can be uploaded alone or shown in a notebook; each picture is also
  saved beside them); file names keep the student id;
- `OUT/results/<student>.json` — Gradescope's `results.json` schema (`score`, `tests`
  of `{name, score, max_score, output}`), so the same checks run inside its autograder.
"""

from __future__ import annotations

import base64
import csv
import html
import json
import re
import shutil
import unicodedata
from collections.abc import Collection, Iterable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

__all__ = ['CheckOutcome', 'StudentReport', 'ascii_name', 'data_uri', 'grader_errors',
           'run_summary',
           'safe_name', 'write_outputs']


@dataclass
class CheckOutcome:
    """One rubric check's result; `output` is Markdown (expected / observed / how to fix)."""

    id: str
    name: str
    score: float
    max_score: float
    output: str = ''
    grader_error: str = ''  # the grader failed here: points kept, to regrade with --only

    @property
    def passed(self) -> bool:
        return self.score >= self.max_score


@dataclass
class StudentReport:
    """Everything graded for one student. `status` is 'graded' unless the run itself failed
    ('error': `error` says why; the checks not reached score 0) or nothing could be run
    ('not graded': a refused notebook; its gradebook row says so)."""

    student: str
    checks: list[CheckOutcome] = field(default_factory=list)
    status: str = 'graded'
    error: str = ''
    images: list[Path] = field(default_factory=list)  # PNG/SVG files shown in the feedback
    title: str = ''  # what was graded, e.g. 'ch6-lab1' or a notebook's name
    elapsed: float = 0.0
    submitted: str = ''  # when the LMS says it was handed in (ISO 8601), if known
    late_days: int = 0
    penalty: float = 0.0  # points taken off for lateness
    notes: list[str] = field(default_factory=list)  # what the sandbox refused the code

    @property
    def earned(self) -> float:
        """The checks' points, before any late penalty."""
        return sum(c.score for c in self.checks)

    @property
    def score(self) -> float:
        """The grade: the checks' points less the late penalty (never below 0)."""
        return max(0.0, self.earned - self.penalty)

    @property
    def max_score(self) -> float:
        return sum(c.max_score for c in self.checks)

    def summary(self) -> str:
        """`alice: 7/10`, one line per student."""
        line = f'{self.student}: {number(self.score)}/{number(self.max_score)}'
        return line if self.status == 'graded' else f'{line} ({self.status}: {self.error})'

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data['images'] = [str(p) for p in self.images]
        data['score'] = self.score
        data['max_score'] = self.max_score
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> StudentReport:
        fields = {k: v for k, v in data.items()
                  if k not in ('checks', 'score', 'max_score', 'images')}
        return cls(**fields, checks=[CheckOutcome(**c) for c in data.get('checks', [])],
                   images=[Path(p) for p in data.get('images', [])])

    def results_json(self) -> dict[str, Any]:
        """Gradescope's autograder `results.json` for this student."""
        data: dict[str, Any] = {
            'score': self.score,
            'output_format': 'md',
            'execution_time': round(self.elapsed, 1),
            'tests': [{'name': c.name or c.id, 'score': c.score, 'max_score': c.max_score,
                       'output': c.output, 'number': c.id} for c in self.checks],
        }
        notes = []
        if self.status != 'graded':
            notes.append(f'Grading ended early ({self.status}): {self.error}')
        if self.late_days:
            notes.append(f'Late by {self.late_days} day(s): {number(self.penalty)} point(s) '
                         'off.')
        if notes:
            data['output'] = '\n\n'.join(notes)
        return data

    def markdown(self, image_names: Sequence[str] = ()) -> str:
        """The feedback page: total, then each check once: its points and explanation."""
        head = f'# Feedback for {self.student}'
        if self.title:
            head += f' — {self.title}'
        lines = [head, '', f'**Score: {number(self.score)} / {number(self.max_score)}**', '']
        if self.late_days:
            lines += [f'> Handed in {self.late_days} day(s) late{self._when()}: '
                      f'{number(self.penalty)} point(s) off the {number(self.earned)} earned.', '']
        if self.status == 'not graded':
            lines += [f'> Not graded: {self.error}', '']
        elif self.status != 'graded':
            lines += [f'> Grading ended early ({self.status}): {self.error}', '']
        for note in self.notes:
            lines += [f'> **Sandbox:** {note}', '']
        for name in image_names:
            lines += [f'![your running graph]({name})', '']
        for c in self.checks:  # each check once: its points, then why
            mark = ('grader error, points kept' if c.grader_error else 'passed' if c.passed
                    else 'partly' if c.score > 0 else 'not met')
            lines += [f'## {c.name or c.id} — {number(c.score)}/{number(c.max_score)} '
                      f'({mark})', '',
                      c.output.strip() or ('Passed.' if c.passed else 'Not met.'), '']
        return '\n'.join(lines)


    def _when(self) -> str:
        return f' ({self.submitted.replace("T", " ")})' if self.submitted else ''


def number(value: float) -> str:
    """`3` for 3.0, `2.5` for 2.5: points as a person writes them."""
    return str(int(value)) if float(value).is_integer() else f'{value:g}'


_UNSAFE = re.compile(r'[^\w.@+-]+')


def safe_name(student: str) -> str:
    """A file name for a student id: the id itself, letters of any script kept (NFC), every
    run of anything else (spaces, slashes, punctuation) one `_`; never a leading dot."""
    name = _UNSAFE.sub('_', unicodedata.normalize('NFC', student)).strip('._')
    return name[:120] or 'student'


def ascii_name(student: str) -> str:
    """`José Núñez_1234567` -> `Jose_Nunez_1234567`: for systems that want ASCII names."""
    def ascii_of(text: str) -> str:
        return unicodedata.normalize('NFKD', text).encode('ascii', 'ignore').decode()

    if all(ascii_of(c) for c in student if c.isalnum()):
        return safe_name(ascii_of(student))
    return safe_name(student)  # a script with no ASCII spelling: keep the id as it is


def _file_names(reports: Sequence[StudentReport], ascii_names: bool = False) -> dict[int, str]:
    """A distinct file name per report (two ids reduced to the same name get `-2`, ...)."""
    names: dict[int, str] = {}
    taken: set[str] = set()
    for i in sorted(range(len(reports)), key=lambda i: reports[i].student):
        r = reports[i]
        base = name = (ascii_name if ascii_names else safe_name)(r.student)
        n = 1
        while name.casefold() in taken:
            n += 1
            name = f'{base}-{n}'
        taken.add(name.casefold())
        names[i] = name
    return names


_MIME = {'.png': 'image/png', '.svg': 'image/svg+xml', '.jpg': 'image/jpeg',
         '.jpeg': 'image/jpeg', '.gif': 'image/gif'}


def data_uri(path: Path) -> str:
    """A picture as a `data:` URI, so a page carries it when uploaded on its own."""
    mime = _MIME.get(path.suffix.lower(), 'application/octet-stream')
    return f'data:{mime};base64,{base64.b64encode(path.read_bytes()).decode()}'


def _to_html(markdown_text: str, title: str) -> str:
    import mistune

    body = mistune.create_markdown(plugins=['table'])(markdown_text)
    return ('<!DOCTYPE html>\n<html><head><meta charset="utf-8">'
            f'<title>{html.escape(title)}</title><style>'
            'body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}'
            'table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.2em .6em}'
            'pre{background:#f6f8fa;padding:.6em;white-space:pre-wrap;overflow-wrap:anywhere}'
            'code{overflow-wrap:anywhere}img{max-width:100%}'
            f'</style></head><body>\n{body}</body></html>\n')


def grader_errors(reports: Sequence[StudentReport]) -> list[tuple[str, list[str]]]:
    """(student, the checks the grader failed on) for every student it failed somewhere:
    their points were kept, and they are to be regraded with `--only`."""
    found = []
    for r in sorted(reports, key=lambda r: r.student):
        checks = [c.id for c in r.checks if c.grader_error]
        if checks or r.status == 'grader error':
            found.append((r.student, checks))
    return found


def run_summary(reports: Sequence[StudentReport]) -> str:
    """The run's last line: how many, who was not fully graded (and why, briefly), and how
    many grader errors there were, with the `--only` that regrades them."""
    short = [r for r in reports if r.status != 'graded']
    line = f'{len(reports)} student(s): {len(reports) - len(short)} fully graded'
    if short:
        names = ', '.join(f'{r.student} ({r.status})'
                          for r in sorted(short, key=lambda r: r.student))
        line = f'{line}, {len(short)} not fully graded: {names}'
    faults = grader_errors(reports)
    if faults:
        count = sum(max(1, len(checks)) for _, checks in faults)
        line += (f'; {count} grader error(s) in {len(faults)} student(s), points kept: '
                 f'regrade with --only {",".join(s for s, _ in faults)}')
    return line


def check_ids(reports: Iterable[StudentReport]) -> list[str]:
    """Every check id, in the order first seen (the gradebook's columns)."""
    ids: dict[str, None] = {}
    for report in reports:
        for c in report.checks:
            ids.setdefault(c.id, None)
    return list(ids)


def write_gradebook(path: Path, reports: Sequence[StudentReport],
                    columns: Sequence[str] | None = None) -> None:
    """grades.csv: a row per student; `late_days,penalty` columns when anyone was late."""
    ids = list(columns) if columns is not None else check_ids(reports)
    late = any(r.late_days for r in reports)
    with path.open('w', newline='') as f:
        writer = csv.writer(f)
        writer.writerow(['student', 'score', 'max_score', *ids]
                        + (['late_days', 'penalty'] if late else []))
        for r in sorted(reports, key=lambda r: r.student):
            earned = {c.id: c.score for c in r.checks}
            if r.status == 'not graded' and not r.checks:  # nothing ran: a row that says so
                writer.writerow([r.student, 'not graded', '', *('' for _ in ids)]
                                + (['', ''] if late else []))
                continue
            writer.writerow([r.student, number(r.score), number(r.max_score),
                             *(number(earned.get(i, 0.0)) for i in ids)]
                            + ([str(r.late_days), number(r.penalty)] if late else []))


def write_outputs(out_dir: str | Path, reports: Sequence[StudentReport],
                  columns: Sequence[str] | None = None,
                  only: Collection[str] | None = None, ascii_names: bool = False) -> Path:
    """Write grades.csv, feedback/<student>.md+.html and results/<student>.json; return OUT.

    `columns` fixes the check-id columns (e.g. the rubric's order); by default every id seen.
    `only`: write feedback and results for these students alone (grades.csv has everyone).
    `ascii_names`: file names transliterated (`José Núñez_12` -> `Jose_Nunez_12`).
    Images are embedded in the pages and copied next to them as `<student>.<name>`.
    """
    out = Path(out_dir)
    (out / 'feedback').mkdir(parents=True, exist_ok=True)
    (out / 'results').mkdir(parents=True, exist_ok=True)
    write_gradebook(out / 'grades.csv', reports, columns)
    names = _file_names(reports, ascii_names)
    for i, r in enumerate(reports):
        if only is not None and r.student not in only:
            continue
        name = names[i]
        images: list[Path] = []
        for image in r.images:
            if Path(image).is_file():
                target = out / 'feedback' / f'{name}.{Path(image).name}'
                if Path(image).resolve() != target.resolve():
                    shutil.copyfile(image, target)
                images.append(target)
        # Both pages embed the pictures: notebook 07 shows the .md as a Markdown output, where
        # a link to a file beside the page is a broken image.
        page = r.markdown([data_uri(p) for p in images])
        (out / 'feedback' / f'{name}.md').write_text(page)
        (out / 'feedback' / f'{name}.html').write_text(_to_html(page, f'Feedback: {r.student}'))
        (out / 'results' / f'{name}.json').write_text(
            json.dumps(r.results_json(), indent=2) + '\n')
    return out
