"""`robot-lab course release DIR`: write or update the student's copy of the course;
`robot-lab course nbgrader DIR`: write an nbgrader course of the kit's exercises."""

from __future__ import annotations

import argparse

HELP = "Release the course (the student's copy), or write an nbgrader course of it"


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
    nbgrader = sub.add_parser(
        'nbgrader', help="Write an nbgrader course of the kit's exercises into DIR",
        description="Write DIR/nbgrader_config.py (course_id, the exchange), "
        "DIR/students/nbgrader_config.py (the students' config) and DIR/source/exNN/ (the "
        "kit's exercises as nbgrader source notebooks). Files already there are kept.",
    )
    nbgrader.add_argument('dest', metavar='DIR', help='The nbgrader course folder')
    nbgrader.add_argument('--course-id', default='robot_lab', metavar='ID',
                          help='nbgrader course_id (default: robot_lab)')
    nbgrader.add_argument('--exchange', metavar='PATH',
                          help='A shared exchange folder (default: DIR/exchange)')
    nbgrader.add_argument('--solutions', metavar='DIR',
                          help="Source notebooks (default: the kit's solutions/)")


def _nbgrader(args: argparse.Namespace) -> int:
    import os

    from robot_lab.grading.nbgrader_course import write_course

    files = write_course(args.dest, course_id=args.course_id, exchange=args.exchange,
                         solutions=args.solutions)

    def shown(path: object) -> str:
        return os.path.relpath(str(path))

    for f in files:
        print(f'{f.action:<6} {shown(f.path)}')
    sources = sorted({f.path.parent.name for f in files if f.path.parent.parent.name == 'source'})
    exchange = args.exchange or os.path.join(args.dest, 'exchange')
    print(f'course {args.course_id!r} in {args.dest}: assignments {", ".join(sources)}; '
          f'exchange {exchange}')
    return 0


def main(args: argparse.Namespace) -> int:
    if args.course_command == 'nbgrader':
        return _nbgrader(args)
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
