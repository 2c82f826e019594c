"""`robot-lab course release DIR`: write or update the student's copy of the course."""

from __future__ import annotations

import argparse

HELP = "Release the course: the student's copy of the notebooks and exercises"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='course_command', metavar='COMMAND', required=True)
    release = sub.add_parser(
        'release', help='Write the student copies (answers removed, checks kept) into DIR',
        description='Write DIR/notebooks and DIR/exercises: answers removed, checks kept, '
        'notebooks trusted. Run again to add what is new; a file the student changed is '
        'never overwritten.',
    )
    release.add_argument('dest', metavar='DIR', help="The student's course folder")
    release.add_argument('--course', metavar='ROOT',
                         help="The course repository (default: the kit's checkout)")
    release.add_argument('--no-sign', action='store_true',
                         help='Do not mark the notebooks trusted in your Jupyter data dir')


def main(args: argparse.Namespace) -> int:
    from robot_lab.grading.release import release_course

    results = release_course(args.dest, args.course, sign=not args.no_sign)
    counts: dict[str, int] = {}
    for r in results:
        counts[r.action] = counts.get(r.action, 0) + 1
        if r.action == 'kept':
            print(f'kept     {r.path}  (you changed it; delete it and release again for '
                  'the new version)')
        elif r.action != 'unchanged':
            print(f'{r.action:<8} {r.path}')
    summary = ', '.join(f'{n} {action}' for action, n in counts.items())
    print(f'{len(results)} notebooks in {args.dest}: {summary}')
    return 0
