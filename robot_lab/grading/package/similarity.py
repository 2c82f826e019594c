"""Which students' code is a copy: `OUT/similarity.html`, judged against the class itself.

Every student's Python (nodes, Python launch files; not `setup.py`, `__init__.py` or tests)
is reduced to its shape — names become `V`, strings `S`, numbers `N`, comments and layout
dropped — so renaming and reformatting do not hide a copy. Fingerprints are chosen from that
shape by winnowing (copydetect's implementation, the algorithm of MOSS). Type annotations
are dropped first (adding or removing them changes nothing). Fingerprints of code every
rclpy solution has anyway never count, nor those made only of such code where two idioms
meet: the package template and robot_lab.grading.package.similarity_idioms (`main()` with
`spin`, timers whose period comes from a parameter, publisher and subscription creation,
parameter declarations, logging, the ROS 2 tutorials' and the lab handout's layouts). A
pair's score is the larger share of one student's remaining code found in the other's.

A pair is named only when its score is an outlier *in this class* (see `decide_threshold`):
honest solutions to one lab resemble each other by a class-specific amount, which a fixed
percentage cannot know. The report shows each named pair's matching lines side by side.
"""

from __future__ import annotations

import ast
import contextlib
import hashlib
import html
import io
import keyword
import statistics
import tempfile
import tokenize
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from robot_lab.grading.package.similarity_idioms import IDIOMS
from robot_lab.grading.package.submission import Submission, copy_submission

__all__ = ['Match', 'SimilarPair', 'Threshold', 'decide_threshold', 'similar_pairs',
           'similarity_report']

K_GRAM = 12  # tokens a fingerprint spans (about one statement)
WINDOW = 4  # winnowing window: any shared run of K_GRAM + WINDOW - 1 tokens is seen
OUTLIER_Z = 3.5  # Iglewicz & Hoaglin: modified z-score above 3.5 is an outlier
# Never name a pair sharing less than FLOOR, however quiet the class: in a small class the
# median and MAD rest on few students, so the floor decides. Measured on the 30 honest
# students of tests/data/class_independent and class_ch6 and 7 renamed or reordered
# copies: honest pairs reach 33 %, copies start at 60 %.
FLOOR = 0.45
CAP = 0.7  # always name a pair sharing more than this, however alike the class
MIN_SHARED = 40  # tokens two students must share to be named at all
_TEMPLATES = Path(__file__).resolve().parents[2] / 'pkg' / 'templates' / 'ament_python'
_SKIP_DIRS = {'build', 'install', 'log', 'test', 'tests', '__pycache__', '.git'}
_SKIP_FILES = {'setup.py', '__init__.py', 'conftest.py'}



@dataclass(frozen=True)
class Shape:
    """A student's code as tokens: each token's shape, its literal form, and its place."""

    coarse: list[str]  # names V, strings S, numbers N (what idioms are matched on)
    fine: list[str]  # names V, strings and numbers kept (what students are compared on)
    origin: list[tuple[str, int]]  # (file relative to the package, line) per token
    sources: dict[str, list[str]]  # file -> its lines


@dataclass(frozen=True)
class Match:
    """One run of matching code in one student's file: lines first..last."""

    file: str
    first: int
    last: int
    code: str


@dataclass(frozen=True)
class SimilarPair:
    a: str
    b: str
    similarity: float  # the larger of the two directions, 0..1
    shared: int  # tokens in common
    matches_a: list[Match] = field(default_factory=list)
    matches_b: list[Match] = field(default_factory=list)


@dataclass(frozen=True)
class Threshold:
    """How this class's threshold was set, to print beside the verdicts."""

    value: float
    median: float
    mad: float
    pairs: int

    def explain(self) -> str:
        return (f'{self.pairs} pair(s) compared; pair scores have median {self.median:.0%} and '
                f'median absolute deviation (MAD) {self.mad:.0%}; a pair is named above '
                f'median + {OUTLIER_Z / 0.6745:.1f}·MAD (a modified z-score above '
                f'{OUTLIER_Z:g}), but never below {FLOOR:.0%} and always above {CAP:.0%}: '
                f'here {self.value:.0%}')


def decide_threshold(scores: Sequence[float]) -> Threshold:
    """The class's own line between resemblance and copying: a robust outlier rule.

    Honest pairs cluster (same lab, same API); a copied pair stands far above the cluster.
    The median and MAD are not moved by a few copies, so the copies stay outliers.
    """
    if not scores:
        return Threshold(CAP, 0.0, 0.0, 0)
    median = statistics.median(scores)
    mad = statistics.median(abs(s - median) for s in scores)
    line = median + OUTLIER_Z / 0.6745 * mad
    return Threshold(min(CAP, max(FLOOR, line)), median, mad, len(scores))


def _literal(value: str) -> str:
    try:
        return repr(ast.literal_eval(value))
    except (ValueError, SyntaxError, MemoryError, RecursionError):
        return value


def _annotations(source: str) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Where the type annotations are ((line, col) from, to): `x: int`, `-> None`.

    Annotations change no behaviour, so adding or dropping them must not hide a copy, nor
    make two honest students who both annotate look alike.
    """
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return []
    found = []
    for node in ast.walk(tree):
        notes: list[ast.expr | None] = []
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            notes.append(node.returns)
        elif isinstance(node, ast.arg | ast.AnnAssign):
            notes.append(node.annotation)
        for note in notes:
            if note is not None and note.end_lineno is not None:
                found.append(((note.lineno, note.col_offset),
                              (note.end_lineno, note.end_col_offset or 0)))
    return found


def _tokens(source: str) -> list[tuple[str, str, int]]:
    """(shape, literal form, line) of each token; a file that does not tokenize is cut there."""
    raw: list[tokenize.TokenInfo] = []
    with contextlib.suppress(tokenize.TokenError, IndentationError, SyntaxError):
        raw.extend(tokenize.generate_tokens(io.StringIO(source).readline))  # kept up to there
    inside = [False] * (len(raw) + 1)  # token i is (part of) an annotation
    notes, at = sorted(_annotations(source)), 0
    for i, tok in enumerate(raw):
        while at < len(notes) and notes[at][1] <= tok.start:
            at += 1
        inside[i] = at < len(notes) and notes[at][0] <= tok.start
    found: list[tuple[str, str, int]] = []
    depth = 0  # inside an f-string (Python 3.12 tokenizes its parts)
    for i, tok in enumerate(raw):
        kind, value = tok.type, tok.string
        name = tokenize.tok_name[kind]
        if inside[i] or (value in (':', '->') and inside[i + 1]):
            continue
        if name == 'FSTRING_START':
            depth += 1
            if depth == 1:
                found.append(('S', 'f-string', tok.start[0]))
        elif name == 'FSTRING_END':
            depth -= 1
        elif depth:
            continue
        elif kind == tokenize.NAME:
            symbol = value if keyword.iskeyword(value) else 'V'
            found.append((symbol, symbol, tok.start[0]))
        elif kind in (tokenize.STRING, tokenize.NUMBER):
            symbol = 'S' if kind == tokenize.STRING else 'N'
            found.append((symbol, _literal(value), tok.start[0]))
        elif kind == tokenize.OP:
            found.append((value, value, tok.start[0]))
        elif kind in (tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT):
            symbol = {tokenize.NEWLINE: ';', tokenize.INDENT: '{'}.get(kind, '}')
            found.append((symbol, symbol, tok.start[0]))
        # comments, blank lines, encoding, end: not code
    return found


def _statements(tokens: list[tuple[str, str, int]]) -> list[list[tuple[str, str, int]]]:
    """Logical lines, without imports and docstrings (nobody copies those to cheat)."""
    lines: list[list[tuple[str, str, int]]] = []
    current: list[tuple[str, str, int]] = []
    for tok in tokens:
        current.append(tok)
        if tok[0] in (';', '{', '}'):
            body = [t for t in current if t[0] not in ('{', '}')]
            head = body[0][0] if body else ''
            if head in ('import', 'from') or [t[0] for t in body] == ['S', ';']:
                current = [t for t in current if t[0] in ('{', '}')]
            lines.append(current)
            current = []
    lines.append(current)
    return lines


def _shape_of(source: str, file: str, code: Shape) -> None:
    for line in _statements(_tokens(source)):
        for coarse, fine, number in line:
            code.coarse.append(coarse)
            code.fine.append(fine)
            code.origin.append((file, number))


def shape(files: dict[str, str]) -> Shape:
    """The tokens of a student's files (name -> source), in name order."""
    code = Shape([], [], [], {n: s.splitlines() for n, s in files.items()})
    for name in sorted(files):
        _shape_of(files[name], name, code)
    return code


def _kgrams(tokens: Sequence[str]) -> list[int]:
    """A stable 63-bit hash of every K_GRAM tokens (not `hash()`: it changes per process)."""
    grams = []
    for i in range(len(tokens) - K_GRAM + 1):
        digest = hashlib.blake2b('\x1f'.join(tokens[i:i + K_GRAM]).encode(), digest_size=8)
        grams.append(int.from_bytes(digest.digest(), 'little') >> 1)
    return grams


def _student_files(submission: Submission, work: Path) -> dict[str, str]:
    folder = copy_submission(submission, work / 'unpacked' / submission.student)
    files = {}
    for path in sorted(folder.rglob('*.py')):
        rel = path.relative_to(folder)
        if _SKIP_DIRS & set(rel.parts[:-1]) or rel.name in _SKIP_FILES or not path.is_file():
            continue
        if path.is_symlink() or path.stat().st_size > 200_000:
            continue
        files[rel.as_posix()] = path.read_text(errors='replace')
    return files


def _idiom_hashes() -> set[int]:
    sources = {'idioms.py': IDIOMS}
    for template in _TEMPLATES.glob('*.py.tmpl'):
        sources[template.name] = template.read_text().replace('{{', '').replace('}}', '')
    return set(_kgrams(shape(sources).coarse))


@dataclass(frozen=True)
class Fingerprints:
    """A student's winnowed fingerprints (hash -> token positions), idioms removed."""

    where: dict[int, list[int]]
    covered: int  # tokens some fingerprint covers

    @classmethod
    def of(cls, code: Shape, idioms: set[int]) -> Fingerprints:
        import numpy as np
        from copydetect.utils import winnow  # type: ignore[import-untyped]

        fine = _kgrams(code.fine)
        if not fine:
            return cls({}, 0)
        coarse = _kgrams(code.coarse)
        common = [0] * (len(code.coarse) + 1)  # +1 / -1: an idiom's k-gram starts / ends
        for pos, gram in enumerate(coarse):
            if gram in idioms:
                common[pos] += 1
                common[pos + K_GRAM] -= 1
        idiom, depth = [], 0  # per token: some idiom's k-gram covers it
        for delta in common[:-1]:
            depth += delta
            idiom.append(depth > 0)
        _selected, positions = winnow(np.array(fine, dtype=np.int64), WINDOW,
                                      remove_duplicates=False)
        where: dict[int, list[int]] = {}
        covered: set[int] = set()
        for pos in sorted({int(p) for p in positions}):
            if all(idiom[pos:pos + K_GRAM]):  # idioms only (where two of them meet, too)
                continue
            where.setdefault(fine[pos], []).append(pos)
            covered.update(range(pos, pos + K_GRAM))
        return cls(where, len(covered))


def _shared(mine: Fingerprints, theirs: Fingerprints) -> list[tuple[int, int]]:
    """The runs of my tokens [start, end) whose fingerprints the other student has too."""
    positions = sorted(p for h in mine.where.keys() & theirs.where.keys()
                       for p in mine.where[h])
    runs: list[tuple[int, int]] = []
    for pos in positions:
        if runs and pos <= runs[-1][1]:
            runs[-1] = (runs[-1][0], max(runs[-1][1], pos + K_GRAM))
        else:
            runs.append((pos, pos + K_GRAM))
    return runs


def _matches(code: Shape, runs: Sequence[tuple[int, int]]) -> list[Match]:
    """Runs of tokens -> the files and lines they came from, with those lines."""
    found: list[Match] = []
    for start, end in runs:
        by_file: dict[str, list[int]] = {}
        for file, line in code.origin[start:end]:
            by_file.setdefault(file, []).append(line)
        for file, lines in by_file.items():
            first, last = min(lines), max(lines)
            if found and found[-1].file == file and first <= found[-1].last + 1:
                first, last = min(first, found[-1].first), max(last, found[-1].last)
                found.pop()  # one block for adjoining runs
            text = '\n'.join(code.sources[file][first - 1:last])
            found.append(Match(file, first, last, text))
    return found


def compare(names: Sequence[str], codes: Sequence[Shape],
            every_pair: bool = False) -> tuple[list[SimilarPair], Threshold]:
    """Every pair's score, the class's threshold, and the pairs above it (highest first);
    `every_pair`: all pairs, named or not (to measure where the line falls)."""
    idioms = _idiom_hashes()
    prints = [Fingerprints.of(c, idioms) for c in codes]
    scored: list[tuple[float, int, int, int, list[tuple[int, int]],
                       list[tuple[int, int]]]] = []
    for i in range(len(codes)):
        for j in range(i + 1, len(codes)):
            runs_i, runs_j = _shared(prints[i], prints[j]), _shared(prints[j], prints[i])
            shared_i = sum(e - s for s, e in runs_i)
            shared_j = sum(e - s for s, e in runs_j)
            score = max(shared_i / prints[i].covered if prints[i].covered else 0.0,
                        shared_j / prints[j].covered if prints[j].covered else 0.0)
            scored.append((score, min(shared_i, shared_j), i, j, runs_i, runs_j))
    threshold = decide_threshold([s[0] for s in scored])
    pairs = [SimilarPair(names[i], names[j], score, shared, _matches(codes[i], ri),
                         _matches(codes[j], rj))
             for score, shared, i, j, ri, rj in scored
             if every_pair or (score > threshold.value and shared >= MIN_SHARED)]
    return sorted(pairs, key=lambda p: -p.similarity), threshold


def similar_pairs(submissions: Sequence[Submission]) -> tuple[list[SimilarPair], Threshold]:
    """The pairs of students whose code is a copy, and how the line was drawn."""
    names, codes = [], []
    with tempfile.TemporaryDirectory(prefix='robot_lab_similarity_') as tmp:
        for sub in submissions:
            try:
                files = _student_files(sub, Path(tmp))
            except Exception:  # an unreadable entry is graded elsewhere, not compared
                continue
            code = shape(files)
            if code.fine:
                names.append(sub.student)
                codes.append(code)
    return compare(names, codes)


def _column(student: str, matches: Sequence[Match]) -> str:
    blocks = ''.join(
        f'<p class="where">{html.escape(m.file)}:{m.first}–{m.last}</p>'
        f'<pre>{html.escape(m.code)}</pre>' for m in matches)
    return f'<div><h3>{html.escape(student)}</h3>{blocks}</div>'


def similarity_report(submissions: Sequence[Submission], out: Path) -> list[SimilarPair]:
    """Write the HTML report of the pairs named (none: a page that says so)."""
    pairs, threshold = similar_pairs(submissions)
    rows = ''.join(
        f'<tr data-a="{html.escape(p.a)}" data-b="{html.escape(p.b)}">'
        f'<td><a href="#p{i}">{html.escape(p.a)}</a></td><td>{html.escape(p.b)}</td>'
        f'<td>{p.similarity:.0%}</td></tr>' for i, p in enumerate(pairs))
    details = ''.join(
        f'<h2 id="p{i}">{html.escape(p.a)} &harr; {html.escape(p.b)} ({p.similarity:.0%})</h2>'
        f'<div class="pair">{_column(p.a, p.matches_a)}{_column(p.b, p.matches_b)}</div>'
        for i, p in enumerate(pairs))
    verdict = (f'{len(pairs)} pair(s) stand out from the class' if pairs
               else 'No pair stands out from the class')
    page = (
        '<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>Similarity report</title>'
        '<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}'
        'td,th{border:1px solid #ccc;padding:.2em .6em}.pair{display:flex;gap:1em}'
        '.pair>div{flex:1;min-width:0}pre{background:#fde8e8;padding:.5em;overflow-x:auto;'
        'font-size:85%}.where{font-family:monospace;margin:.6em 0 0}'
        '</style></head><body>\n<h1>Similarity report</h1>\n'
        f'<p>{len(submissions)} submissions compared. {verdict}.</p>\n'
        f'<p class="threshold">{html.escape(threshold.explain())}.</p>\n'
        '<p>Not compared: setup.py, __init__.py, tests, and the code every rclpy solution '
        'shares (the package template, main() with spin, timers from parameters, publisher '
        'and subscription creation, parameter declarations, logging). A named pair is a '
        'reason to look at the lines below, not a verdict.</p>\n'
        + (f'<table><tr><th>student</th><th>student</th><th>similarity</th></tr>{rows}'
           '</table>\n' if pairs else '')
        + details + '</body></html>\n')
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(page)
    return pairs
