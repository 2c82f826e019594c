"""`ament_copyright [paths]`: every source file starts with a copyright notice and a known
license header; a repository root has a LICENSE and a CONTRIBUTING.md.

Same command line, messages and exit code as ament_lint's ament_copyright (Jazzy): errors
go to stderr as `path: could not find copyright notice`, then `N errors, checked M files`
(exit 1) or `No problems found, checked M files` (exit 0).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from ament_copyright import COPYRIGHT_NAMES, LICENSES, UNKNOWN_IDENTIFIER

EXTENSIONS = ('c', 'cc', 'cpp', 'cxx', 'h', 'hh', 'hpp', 'hxx', 'cmake', 'py')
SOURCE, CONTRIBUTING, LICENSE = 'source', 'CONTRIBUTING.md', 'LICENSE'

_YEARS = r'\d{4}(?:-\d{4})?(?:,\s*\d{4}(?:-\d{4})?)*'
_COPYRIGHT = re.compile(
    r'^[^\n\r]?\s*(?:\\copyright\s*)?copyright(?:\s+\(c\))?\s+(' + _YEARS + r'),?\s+([^\n\r]+)$',
    re.IGNORECASE | re.MULTILINE)


@dataclass
class Checked:
    """One file's verdict: what ament_copyright prints for it and whether it is an error."""

    path: str
    kind: str
    message: str
    error: bool
    copyrights: list[str] = field(default_factory=list)


def _is_repository_root(path: str) -> bool:
    return os.path.exists(os.path.join(path, '.git')) or os.path.exists(os.path.join(path, '.hg'))


def collect(paths: Sequence[str], excludes: Sequence[str]) -> dict[str, str]:
    """The files to check: sources by extension (not in `.`/`_` folders, not a package's
    setup.py), plus LICENSE and CONTRIBUTING.md at repository roots."""
    excluded = {os.path.realpath(p) for pattern in excludes for p in _glob(pattern)}
    found: dict[str, str] = {}

    def add_root_files(folder: str) -> None:
        for kind in (CONTRIBUTING, LICENSE):
            found[os.path.join(folder, kind)] = kind

    for path in paths:
        if os.path.isdir(path):
            for folder, dirs, files in os.walk(path):
                if 'AMENT_IGNORE' in dirs + files:
                    dirs[:] = []
                    continue
                if _is_repository_root(folder):
                    add_root_files(folder)
                dirs[:] = sorted(d for d in dirs if d[0] not in '._')
                for name in sorted(files):
                    if name == 'setup.py' and os.path.exists(os.path.join(folder, 'package.xml')):
                        continue
                    full = os.path.join(folder, name)
                    if name.rsplit('.', 1)[-1] in EXTENSIONS and '.' in name \
                            and os.path.realpath(full) not in excluded:
                        found[full] = SOURCE
        elif (os.path.isfile(path) and path.rsplit('.', 1)[-1] in EXTENSIONS
              and os.path.realpath(path) not in excluded):
            found[path] = SOURCE
        if _is_repository_root(os.path.dirname(path)) and os.path.basename(path) in (
                CONTRIBUTING, LICENSE):
            found[path] = os.path.basename(path)
    return {os.path.normpath(p): kind for p, kind in found.items()}


def _glob(pattern: str) -> list[str]:
    import glob

    return glob.glob(pattern)


def _comment_block(text: str, path: str) -> str:
    """The first comment block after shebang/coding lines, comment markers removed."""
    lines = text.splitlines()
    i = 0
    while i < len(lines) and re.match(r'^\s*#(!|.*coding[:=])', lines[i]):
        i += 1
    while i < len(lines) and not lines[i].strip():
        i += 1
    block: list[str] = []
    hash_style = path.endswith(('.py', '.cmake')) or os.path.basename(path) == 'CMakeLists.txt'
    if hash_style:
        while i < len(lines) and lines[i].lstrip().startswith('#'):
            block.append(re.sub(r'^\s*# ?', '', lines[i]))
            i += 1
    elif i < len(lines) and lines[i].lstrip().startswith('//'):
        while i < len(lines) and lines[i].lstrip().startswith('//'):
            block.append(re.sub(r'^\s*// ?', '', lines[i]))
            i += 1
    elif i < len(lines) and lines[i].lstrip().startswith('/*'):
        while i < len(lines):
            line = re.sub(r'^\s*(/\*+|\*+/?)\s?', '', lines[i])
            block.append(line.replace('*/', ''))
            if '*/' in lines[i]:
                break
            i += 1
    return '\n'.join(block)


def _normal(text: str) -> str:
    return ' '.join(text.split())


def _license_of(text_after_copyright: str, headers: bool) -> str:
    body = _normal(text_after_copyright)
    for key, lic in LICENSES.items():
        known = lic.header.split('\n', 1)[1] if headers else lic.license_file
        if known and _normal(known) and body.startswith(_normal(known)):
            return key
    return UNKNOWN_IDENTIFIER


def check_file(path: str, kind: str) -> Checked:
    """ament_copyright's verdict on one file."""
    if not os.path.exists(path):
        return Checked(path, kind, 'file not found', True)
    text = Path(path).read_text(errors='replace')
    if kind != SOURCE:
        if not text.strip():
            return Checked(path, kind, 'file empty', True)
        ident = _license_of(text, headers=False) if kind == LICENSE else (
            'contributing' if text.strip() else UNKNOWN_IDENTIFIER)
        return Checked(path, kind, ident, ident == UNKNOWN_IDENTIFIER)
    if not text.strip():
        return Checked(path, kind, 'file empty', False)
    block = _comment_block(text, path)
    copyrights = [f'{m.group(2).strip()} ({m.group(1)})' for m in _COPYRIGHT.finditer(block)]
    if not copyrights:
        return Checked(path, kind, 'could not find copyright notice', True)
    last = list(_COPYRIGHT.finditer(block))[-1]
    ident = _license_of(block[last.end():], headers=True)
    return Checked(path, kind, f'copyright={", ".join(copyrights)}, license={ident}',
                   ident == UNKNOWN_IDENTIFIER, copyrights)


def add_missing(files: dict[str, str], holder: str, key: str, verbose: bool) -> None:
    """Prepend the license header to sources without a notice; write missing root files."""
    lic = LICENSES[key]
    header = lic.header.format(copyright=f'Copyright {time.strftime("%Y")} {holder}')
    for path, kind in sorted(files.items()):
        if kind == SOURCE:
            verdict = check_file(path, kind)
            if verdict.copyrights or verdict.message == 'file empty':
                if verbose:
                    print(' ', path)
                continue
            prefix = '# ' if path.endswith(('.py', '.cmake')) else '// '
            lines = [(prefix + line).rstrip() for line in header.rstrip('\n').splitlines()]
            text = Path(path).read_text()
            keep: list[str] = []
            rest = text.splitlines(keepends=True)
            while rest and re.match(r'^\s*#(!|.*coding[:=])', rest[0]):
                keep.append(rest.pop(0))
            Path(path).write_text(''.join(keep) + '\n'.join(lines) + '\n\n' + ''.join(rest))
            print('*', path)
        elif not os.path.exists(path):
            Path(path).write_text(lic.license_file if kind == LICENSE else '')
            print('+', path)


def _xunit(report: list[Checked], testname: str, seconds: float) -> str:
    failures = sum(1 for r in report if r.error)
    cases = []
    for r in report:
        case = f'  <testcase name={quoteattr(r.path)} classname="{testname}"'
        if r.error:
            case += f'>\n    <failure message={quoteattr(r.message)}/>\n  </testcase>'
        else:
            case += '/>'
        cases.append(case)
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<testsuite name="{testname}" '
            f'tests="{len(report)}" failures="{failures}" time="{seconds:.3f}">\n'
            + '\n'.join(cases) + f'\n  <system-out>{escape("checked")}</system-out>\n'
            '</testsuite>\n')


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description='Check code files for copyright and license information.',
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument('paths', nargs='*', default=[os.curdir],
                        help='The files or directories to check.')
    parser.add_argument('--exclude', metavar='filename', nargs='*', default=[],
                        dest='excludes', help='The filenames to exclude.')
    group = parser.add_mutually_exclusive_group()
    group.add_argument('--add-missing', nargs=2, metavar=('COPYRIGHT_NAME', 'LICENSE'),
                       help='Add missing copyright notice and license information using the '
                       'passed copyright holder and license')
    group.add_argument('--list-copyright-names', action='store_true',
                       help='List names of known copyright holders')
    group.add_argument('--list-licenses', action='store_true',
                       help='List names of known licenses')
    group.add_argument('--xunit-file', help='Generate a xunit compliant XML file')
    parser.add_argument('--verbose', action='store_true',
                        help='Show all files instead of only the ones with errors')
    args = parser.parse_args(sys.argv[1:] if argv is None else list(argv))

    if args.list_copyright_names:
        for key, name in sorted(COPYRIGHT_NAMES.items()):
            print(f'{key}: {name}')
        return 0
    if args.list_licenses:
        for key, lic in sorted(LICENSES.items()):
            print(f'{key}: {lic.name}')
        return 0
    started = time.time()
    files = collect(args.paths, args.excludes)
    if not files:
        print('No repository roots and files found')
    if args.add_missing:
        holder, key = args.add_missing
        if key not in LICENSES:
            parser.error("'LICENSE' argument must be a known license name. Use the "
                         "'--list-licenses' options to see alist of valid license names.")
        add_missing(files, COPYRIGHT_NAMES.get(holder, holder), key, args.verbose)
        return 0
    report = [check_file(path, kind) for path, kind in sorted(files.items())]
    for r in report:
        if args.verbose or r.error:
            print(f'{r.path}: {r.message}', file=sys.stderr if r.error else sys.stdout)
    errors = sum(1 for r in report if r.error)
    if errors:
        print(f'{errors} errors, checked {len(report)} files', file=sys.stderr)
    else:
        print(f'No problems found, checked {len(report)} files')
    if args.xunit_file:
        out = Path(args.xunit_file)
        name = out.name.removesuffix('.xml').removesuffix('.xunit')
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(_xunit(report, f'{out.parent.name}.{name}', time.time() - started))
    return 1 if errors else 0


if __name__ == '__main__':
    sys.exit(main())
