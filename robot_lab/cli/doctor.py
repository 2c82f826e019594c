"""`robot-lab doctor [PACKAGE_DIR]`: a package's mistakes with file:line and fix, or the
environment as a checklist; exits 1 when something is an error."""

from __future__ import annotations

import argparse

HELP = 'Check a package (setup.py, package.xml, setup.cfg, params) or the ROS environment'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('package_dir', nargs='?',
                        help='The package folder (holding package.xml); without it, the '
                        'environment is checked')


def main(args: argparse.Namespace) -> int:
    from robot_lab.pkg.doctor import doctor

    report = doctor(args.package_dir)
    print(report)
    return 0 if report.ok else 1
