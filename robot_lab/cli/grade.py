"""`robot-lab grade SUBMISSION... [--json]`: run submissions headless and score them."""

from __future__ import annotations

import argparse
import json
import sys

HELP = 'Grade submitted exercise notebooks (runs each headless, scores its check cells)'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('submissions', nargs='+', metavar='SUBMISSION',
                        help='A submitted .ipynb, or a folder of them')
    parser.add_argument('--json', action='store_true',
                        help='Print JSON for gradebooks (an object, or a list for several)')
    parser.add_argument('--timeout', type=float, default=60.0, metavar='S',
                        help='Seconds a cell may run before it is interrupted (default: 60)')
    parser.add_argument('--total-timeout', type=float, default=900.0, metavar='S',
                        help='Seconds a whole submission may run (default: 900)')
    parser.add_argument('-j', '--jobs', type=int, default=1, metavar='N',
                        help='Grade N submissions at a time, each in its own ROS domain '
                        '(the domain id, then the next N-1)')
    parser.add_argument('--domain-id', type=int, metavar='N',
                        help='ROS_DOMAIN_ID for the submissions (default: ROS_DOMAIN_ID)')
    parser.add_argument('--solutions', metavar='DIR',
                        help="Solutions whose check cells are used (default: the kit's)")
    parser.add_argument('--executed', metavar='DIR',
                        help='Also save each executed notebook there as NAME.graded.ipynb')
    parser.add_argument('--executed-as', metavar='FILE', help=argparse.SUPPRESS)


def main(args: argparse.Namespace) -> int:
    from robot_lab.grading.grade import GradeResult, grade, grade_many, submissions

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
            print(r.summary())
    return 0
