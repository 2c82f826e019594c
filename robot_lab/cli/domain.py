"""`robot-lab domain list|release USER`: the host's ROS domain registry, for a hub's admin."""

from __future__ import annotations

import argparse

HELP = "Show the host's ROS domain registry, or free a user's domain"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='domain_command', metavar='COMMAND', required=True)
    sub.add_parser('list', help='Every user with a domain, and the leases of running jobs',
                   description='The registry named by ROBOT_LAB_DOMAIN_REGISTRY (a hub sets '
                   "it for its users' servers), else a hub's /srv/robot_lab/domains.json, "
                   'else /var/tmp/robot_lab/domains.json.')
    release = sub.add_parser('release', help="Free a user's domain (a student who left)",
                             description="Free USER's domain: a Unix name, a hub name "
                             '(its Unix user jupyter-NAME under The Littlest JupyterHub) '
                             'or a uid. Exit 1 if USER has no domain.')
    release.add_argument('user', metavar='USER')


def main(args: argparse.Namespace) -> int:
    from robot_lab.domain import listing, release_user

    if args.domain_command == 'release':
        unix, freed = release_user(args.user)
        print(f'{unix}: domain {freed} freed')
    else:
        print('\n'.join(listing()))
    return 0
