"""`robot-lab grade SUBMISSION... [--json]`: run submissions headless and score them."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

HELP = 'Grade submitted exercise notebooks (runs each headless, scores its check cells)'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('submissions', nargs='+', metavar='SUBMISSION',
                        help='A submitted .ipynb, or a folder of them')
    parser.add_argument('--json', action='store_true',
                        help='Print JSON for gradebooks (an object, or a list for several)')
    parser.add_argument('--timeout', type=float, default=60.0, metavar='S',
                        help='Seconds a cell may run before it is interrupted (default: 60)')
    parser.add_argument('--solutions', metavar='DIR',
                        help="Solutions whose check cells are used (default: the kit's)")
    parser.add_argument('--domain-id', type=int, metavar='N',
                        help='ROS_DOMAIN_ID for the submissions (default: ROS_DOMAIN_ID)')
    parser.add_argument('--executed', metavar='DIR',
                        help='Also save each executed notebook there as NAME.graded.ipynb')


def main(args: argparse.Namespace) -> int:
    from robot_lab.grading.grade import grade, submissions

    paths = submissions(args.submissions)
    out = Path(args.executed) if args.executed else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    results = []
    for path in paths:
        executed = out / f'{path.stem}.graded.ipynb' if out is not None else None
        result = grade(path, cell_timeout=args.timeout, solutions_dir=args.solutions,
                       executed=executed, domain_id=args.domain_id)
        results.append(result)
        if not args.json:
            print(result.table(), flush=True)
    if args.json:
        data = [r.to_dict() for r in results]
        print(json.dumps(data[0] if len(data) == 1 else data, indent=2))
    elif len(results) > 1:
        print()
        for r in results:
            print(r.summary())
    return 0
