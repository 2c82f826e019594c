"""`robot-lab grade SUBMISSION... [--json]`: run submissions headless and score them.

Notebooks by default; with `--lab LAB` (or `--rubric FILE`) package submissions:
`robot-lab grade DIR --lab ch6-lab1 -o OUT --jobs 2` (robot_lab.grading.package.grade).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

HELP = ("Grade submitted exercise notebooks, or with --lab a class's ROS 2 packages "
        '(build, launch, watch, score)')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('submissions', nargs='*', metavar='SUBMISSION',
                        help='A submitted .ipynb, or a folder of them; with --lab: a folder '
                        'with one folder or .zip per student (or one package folder)')
    parser.add_argument('--lab', metavar='LAB',
                        help='Grade ROS 2 packages for this lab (ch6-lab1, lab1.3)')
    parser.add_argument('--rubric', metavar='FILE',
                        help="A rubric YAML (a copy of a shipped one) instead of the lab's")
    parser.add_argument('--print-rubric', action='store_true',
                        help="Print the lab's rubric YAML (to copy, edit and pass to --rubric)")
    parser.add_argument('--list', action='store_true',
                        help='With --lab: list each student and the package found, grade nothing')
    parser.add_argument('-o', '--out', metavar='OUT',
                        help='Write OUT/grades.csv, OUT/feedback/, OUT/results/ '
                        '(Gradescope), OUT/similarity.html')
    parser.add_argument('--json', action='store_true',
                        help='Print JSON for gradebooks (an object, or a list for several)')
    parser.add_argument('--timeout', type=float, default=60.0, metavar='S',
                        help='Seconds a cell may run before it is interrupted (default: 60)')
    parser.add_argument('--total-timeout', type=float, default=900.0, metavar='S',
                        help='Seconds a whole submission may run (default: 900)')
    parser.add_argument('-j', '--jobs', type=int, default=1, metavar='N',
                        help='Grade N submissions at a time, each in its own ROS domain '
                        "leased from the host's registry")
    parser.add_argument('--domain-id', type=int, metavar='N',
                        help='ROS_DOMAIN_ID to grade in (notebooks: one after the other; '
                        'default: domains leased from the registry)')
    parser.add_argument('--solutions', metavar='DIR',
                        help="Solutions whose check cells are used (default: the kit's)")
    parser.add_argument('--executed', metavar='DIR',
                        help='Also save each executed notebook there as '
                        'STUDENT/EXERCISE.graded.ipynb')
    parser.add_argument('--executed-as', metavar='FILE', help=argparse.SUPPRESS)
    lms = parser.add_argument_group('with --lab: regrading, the LMS, late hand-ins')
    lms.add_argument('--only', metavar='ID[,ID...]',
                     help='Regrade only these students (ids as in grades.csv) and merge '
                     'them into the existing OUT: their rows replaced, the others untouched')
    lms.add_argument('--roster', metavar='FILE',
                     help="Moodle's grading worksheet or Canvas's gradebook export (CSV): "
                     'write it back filled as OUT/moodle-grades.csv or OUT/canvas-grades.csv')
    lms.add_argument('--roster-column', metavar='NAME',
                     help="Canvas: the assignment column to fill, e.g. 'Lab 1 (1234)'")
    lms.add_argument('--due', metavar="'YYYY-MM-DD HH:MM'",
                     help="The deadline; late hand-ins lose --late-penalty per day (the "
                     "LMS's submission time: Moodle's worksheet, Canvas's LATE mark)")
    lms.add_argument('--ascii-names', action='store_true',
                     help='Feedback file names transliterated to ASCII (Jose_Nunez_1234567) '
                     'instead of the student id as the LMS spells it')
    lms.add_argument('--late-penalty', type=float, default=10.0, metavar='PCT',
                     help='Percent of the maximum taken off per day late (default: 10)')
    parser.add_argument('--gradescope-autograder', metavar='ZIP',
                        help='With --lab/--rubric: write a Gradescope autograder zip '
                        '(setup.sh, run_autograder) that grades with the same checks')
    parser.add_argument('--no-sandbox', action='store_true',
                        help="Packages: grade on a machine that cannot make namespaces "
                        "(students' code then runs as you, with your files and network)")


def _list(paths: list[str]) -> int:
    """Each student, what they handed in, and where their package is (or why not)."""
    import tempfile
    from pathlib import Path

    from robot_lab.errors import RobotLabError
    from robot_lab.grading.package.submission import find_submissions, unpack

    entries = [e for path in paths for e in find_submissions(path)]
    width = max([len(e.student) for e in entries] + [7])
    print(f'{"student":<{width}}  package found')
    for entry in entries:
        with tempfile.TemporaryDirectory() as tmp:
            try:
                package = unpack(entry, Path(tmp))
                rel = package.relative_to(Path(tmp))
                where = 'its top' if rel == Path('.') else f'{rel}/'
                found = f'{entry.source.name}: package.xml at {where}'
            except RobotLabError as err:
                found = f'{entry.source.name}: NOT GRADABLE: {err.message}'
        print(f'{entry.student:<{width}}  {found}')
    print(f'{len(entries)} student(s)')
    return 0


def _packages(args: argparse.Namespace) -> int:
    from robot_lab.grading.late import LatePolicy, parse_due
    from robot_lab.grading.package.grade import grade_class, resolve_rubric
    from robot_lab.grading.package.sandbox import check_can_contain
    from robot_lab.grading.report import StudentReport, number, run_summary

    if args.domain_id is not None:
        os.environ['ROS_DOMAIN_ID'] = str(args.domain_id)
    rubric = resolve_rubric(args.lab, args.rubric)
    if args.list:
        return _list(args.submissions)
    check_can_contain(args.no_sandbox)

    def table(report: StudentReport) -> str:
        width = max([len(c.id) for c in report.checks] + [5])
        lines = [f'{report.student}', f'  {"check":<{width}}  points']
        lines += [f'  {c.id:<{width}}  {number(c.score):>3}/{number(c.max_score)}'
                  for c in report.checks]
        lines.append(report.summary())
        return '\n'.join(lines)

    late = LatePolicy(parse_due(args.due), args.late_penalty / 100) if args.due else None
    only = [s.strip() for s in args.only.split(',') if s.strip()] if args.only else None
    if (only or args.roster) and not args.out:
        print('robot-lab grade: error: --only and --roster need -o OUT (the class folder)',
              file=sys.stderr)
        return 2
    run = grade_class(args.submissions, rubric, args.out, jobs=args.jobs, only=only,
                      late=late, roster=args.roster, roster_column=args.roster_column,
                      ascii_names=args.ascii_names,
                      progress=(not args.json and sys.stderr.isatty()) or bool(args.out))
    reports = run.reports
    if args.json:
        data = [r.to_dict() for r in reports]
        json.dump(data[0] if len(data) == 1 else data, sys.stdout, indent=2)
        print()
    elif len(reports) == 1 and not args.out:
        print(reports[0].markdown([str(p) for p in reports[0].images]))
    else:
        for r in reports:
            print(r.summary() if args.out else table(r))
    shown = sys.stderr if args.json else sys.stdout
    if run.outputs is not None:
        done = run.outputs
        merged = f' ({len(reports)} regraded, merged into {len(done.everyone)})' if only else ''
        wrote = 'grades.csv, feedback/, results/, summary.html' + (
            ', similarity.html' if run.similarity is not None else '')
        print(f'wrote {args.out}/: {wrote}{merged}', file=shown)
        if done.previous:
            changed = ', '.join(str(c) for c in done.changes) or 'none'
            print(f'scores changed since the last run: {changed}', file=shown)
        if done.roster is not None:
            for line in done.roster.lines():
                print(line, file=shown)
    for r in reports:
        if r.status != 'graded':
            print(f'robot-lab grade: {r.student} not fully graded ({r.status}): {r.error}',
                  file=sys.stderr)
    print(run_summary(reports), file=shown)
    return 0  # the grader ran: each student's problems are in their row and feedback


def main(args: argparse.Namespace) -> int:
    if args.print_rubric:
        from robot_lab.grading.package.rubric import rubric_path

        print(rubric_path(args.lab or 'ch6-lab1').read_text(), end='')
        return 0
    if args.gradescope_autograder:
        from robot_lab.grading.package.grade import resolve_rubric
        from robot_lab.grading.package.gradescope import write_autograder

        if not (args.lab or args.rubric):
            print('robot-lab grade: error: --gradescope-autograder needs --lab LAB or '
                  '--rubric FILE', file=sys.stderr)
            return 2
        rubric = resolve_rubric(args.lab, args.rubric)
        path = write_autograder(args.gradescope_autograder, rubric)
        print(f'wrote {path}: upload it in Gradescope (Configure Autograder → Zip file); '
              f'it grades {rubric.lab} with the same checks')
        return 0
    if not args.submissions:
        print('robot-lab grade: error: the following arguments are required: SUBMISSION',
              file=sys.stderr)
        return 2
    if args.lab or args.rubric:
        return _packages(args)
    from robot_lab.grading.notebook.batch import grade_many
    from robot_lab.grading.notebook.grade import GradeResult, grade, submissions

    def show(result: GradeResult) -> None:
        if not args.json:
            print(result.table(), flush=True)

    if args.executed_as:  # one submission, for a parent grader running jobs
        [path] = submissions(args.submissions)
        results = [grade(path, cell_timeout=args.timeout, solutions_dir=args.solutions,
                         domain_id=args.domain_id, executed=args.executed_as,
                         total_timeout=args.total_timeout)]
    else:
        results = grade_many(args.submissions, jobs=args.jobs, domain_id=args.domain_id,
                             executed_dir=args.executed, on_result=show,
                             cell_timeout=args.timeout, solutions_dir=args.solutions,
                             total_timeout=args.total_timeout)
    if args.json:
        data = [r.to_dict() for r in results]
        json.dump(data[0] if len(data) == 1 else data, sys.stdout, indent=2)
        print()
    elif len(results) > 1:
        print()
        for r in results:
            print(f'{r.student}: {r.summary()}' if r.student else r.summary())
    if args.out and not args.executed_as:
        from robot_lab.grading.notebook.batch import student_reports
        from robot_lab.grading.report import write_outputs

        reports = student_reports(results)
        write_outputs(args.out, reports)
        print(f'wrote {args.out}/grades.csv, feedback/ and results/ for {len(reports)} '
              'student(s)', file=sys.stderr if args.json else sys.stdout)
    # The rule for notebooks and labs alike: 0 whenever the grader ran; a notebook it
    # refused is a "not graded" row and a line on stderr, not a failed run.
    refused = [r for r in results if r.status == 'error' and not r.checks]
    for r in refused:
        print(f'robot-lab grade: could not grade {r.notebook}: {r.detail}', file=sys.stderr)
    return 0
