"""`robot-lab doctor [PACKAGE_DIR]`: a package's mistakes with file:line and fix, or the
environment as a checklist; exits 1 when something is an error.

`ros2 doctor --report` (the ros2doctor tutorial) prints ros2doctor's report sections in its
format: PLATFORM INFORMATION, RMW MIDDLEWARE, ROS 2 INFORMATION, TOPIC LIST.
"""

from __future__ import annotations

import argparse

HELP = 'Check a package (setup.py, package.xml, setup.cfg, params) or the ROS environment'

# ros2doctor's TopicReport leaves these out (SKIP_TOPICS)
_SKIP_TOPICS = ('/parameter_events', '/rosout')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('package_dir', nargs='?',
                        help='The package folder (holding package.xml); without it, the '
                        'environment is checked')
    group = parser.add_mutually_exclusive_group(required=False)
    group.add_argument('--report', '-r', action='store_true', help='Print all reports.')
    group.add_argument('--report-failed', '-rf', action='store_true',
                       help='Print reports of failed checks only.')
    parser.add_argument('--exclude-packages', '-ep', action='store_true',
                        help='Exclude package checks or report.')
    parser.add_argument('--include-warnings', '-iw', action='store_true',
                        help='Include warnings as failed checks. Warnings are ignored by default.')


def main(args: argparse.Namespace) -> int:
    from robot_lab.pkg.doctor import doctor

    if args.report and args.package_dir is None:
        _print_reports()
        return 0
    report = doctor(args.package_dir)
    print(report)
    if args.package_dir is None:
        _print_capabilities()
    if args.report_failed and not report.ok:
        _print_reports()
    return 0 if report.ok else 1


def _print_capabilities() -> None:
    """What this machine offers the kit from Linux, and what the kit does without each."""
    from robot_lab.linux.capabilities import DISABLE_VARIABLE, table

    rows = table()
    width = max(len(row.name) for row in rows)
    print(f'\nLinux capabilities ({DISABLE_VARIABLE}=NAME,... turns one off):')
    print(f'  {"capability":{width}}  here  without it, the kit')
    for row in rows:
        print(f'  {row.name:{width}}  {"yes" if row.available else "no ":4}  {row.fallback}')
        if row.why_not:
            print(f'  {"":{width}}        (missing: {row.why_not})')


def _print_reports() -> None:
    for name, items in _reports():
        print('\n  ', name)
        width = max([8, *(len(key) + 4 for key, _ in items if len(key) >= 8)])
        for key, value in items:
            print(f'{key:{width}}: {value}')


def _reports() -> list[tuple[str, list[tuple[str, object]]]]:
    """ros2doctor's report sections (api/platform.py, rmw.py, topic.py), in its order."""
    import platform

    from rclpy.utilities import get_rmw_implementation_identifier

    from robot_lab.graph.discovery import get_session
    from robot_lab.graph.topics import topic_list

    sess = get_session(None)
    topics: list[tuple[str, object]] = []
    for name, _types in topic_list(session=sess):
        if name not in _SKIP_TOPICS:
            topics += [('topic', name), ('publisher count', sess.node.count_publishers(name)),
                       ('subscriber count', sess.node.count_subscribers(name))]
    return [
        ('PLATFORM INFORMATION', [('system', platform.system()),
                                  ('platform info', platform.platform()),
                                  ('release', platform.release()),
                                  ('processor', platform.processor())]),
        ('ROS 2 INFORMATION', [('distribution name', 'jazzy'),
                               ('distribution type', 'ros2'),
                               ('distribution status', 'active'),
                               ('release platforms',
                                {'debian': ['bookworm'], 'rhel': ['9'], 'ubuntu': ['noble']})]),
        ('RMW MIDDLEWARE', [('middleware name', get_rmw_implementation_identifier())]),
        ('TOPIC LIST', topics or [('topic', 'none'), ('publisher count', 0),
                                  ('subscriber count', 0)]),
    ]
