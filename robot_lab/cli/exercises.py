"""`robot-lab exercises build [--check]`: regenerate exercises/ from solutions/."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = 'Generate the exercise notebooks from the solution notebooks'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='exercises_command', metavar='COMMAND', required=True)
    build = sub.add_parser(
        'build', help='Write exercises/*.ipynb from solutions/*.ipynb',
        description='Write exercises/*.ipynb from solutions/*.ipynb: solution blocks '
        'replaced by placeholders, outputs cleared.',
    )
    build.add_argument('--check', action='store_true',
                       help='Write nothing; exit 1 if exercises/ is out of date')
    build.add_argument('--solutions', metavar='DIR', help="Solutions folder (default: the kit's)")
    build.add_argument('--exercises', metavar='DIR', help="Exercises folder (default: the kit's)")


def _show(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def main(args: argparse.Namespace) -> int:
    from robot_lab.grading.exercises import build_exercises

    results = build_exercises(args.solutions, args.exercises, check=args.check)
    stale = [r for r in results if not r.up_to_date]
    if args.check:
        for r in stale:
            why = 'no longer has a solution' if not r.solution.is_file() else 'is out of date'
            print(f'{_show(r.exercise)} {why}', file=sys.stderr)
        if stale:
            print('run: robot-lab exercises build', file=sys.stderr)
            return 1
        print(f'{len(results)} exercises up to date')
        return 0
    for r in results:
        if r.up_to_date:
            continue
        verb = 'removed' if not r.solution.is_file() else 'wrote'
        print(f'{verb} {_show(r.exercise)}')
    print(f'{len(results)} exercises, {len(stale)} changed')
    return 0
