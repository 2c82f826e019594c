"""`robot-lab param list|get|set|delete|describe|dump|load`: prints what `ros2 param …` prints.

Each verb asks the graph daemon first, whose warm session has the node's parameter
services already discovered; without one it asks the node itself (and starts a daemon for
the next command, as the graph verbs do).
"""

from __future__ import annotations

import argparse
import re
import sys
from typing import Any

from robot_lab.cli import run_sub_verb
from robot_lab.cli.daemon import add_no_daemon, ask_daemon

HELP = 'Various param related sub-commands'

# A param answer may wait for the node (5 s) and then for its reply (5 s), longer for
# `list` over every node: a daemon that takes longer than the graph verbs' 8 s is still
# answering, and asking the node again would set a parameter twice.
_ANSWER_TIMEOUT = 60.0

# ParameterType -> the label `ros2 param get` prints before the value
_GET_LABELS = {
    1: 'Boolean value is:', 2: 'Integer value is:', 3: 'Double value is:',
    4: 'String value is:', 5: 'Byte values are:', 6: 'Boolean values are:',
    7: 'Integer values are:', 8: 'Double values are:', 9: 'String values are:',
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest='param_verb', metavar='VERB')

    lister = sub.add_parser('list', help='Output a list of available parameters')
    lister.add_argument('node_name', nargs='?', help='Name of the ROS node')
    lister.add_argument('--filter', nargs=1, help='Only parameters matching the regex '
                        'expression will be showed. Supports `re` regex syntax.')
    lister.add_argument('--param-prefixes', nargs='+', default=[],
                        help='Only list parameters with the provided prefixes')
    lister.add_argument('--include-hidden-nodes', action='store_true',
                        help='Consider hidden nodes as well')
    lister.add_argument('--param-type', action='store_true',
                        help='Print parameter types with parameter names')
    add_no_daemon(lister)

    get = sub.add_parser('get', help='Get parameter')
    get.add_argument('node_name', help='Name of the ROS node')
    get.add_argument('parameter_name', help='Name of the parameter')
    get.add_argument('--hide-type', action='store_true', help='Hide the type information')

    setter = sub.add_parser('set', help='Set parameter')
    setter.add_argument('node_name', help='Name of the ROS node')
    setter.add_argument('parameter_name', help='Name of the parameter')
    setter.add_argument('value', help='Value of the parameter')

    delete = sub.add_parser('delete', help='Delete parameter')
    delete.add_argument('node_name', help='Name of the ROS node')
    delete.add_argument('parameter_name', help='Name of the parameter')

    describe = sub.add_parser('describe', help='Show descriptive information about declared '
                              'parameters')
    describe.add_argument('node_name', help='Name of the ROS node')
    describe.add_argument('parameter_names', nargs='+', help='Names of the parameters')

    dump = sub.add_parser('dump', help='Show all of the parameters of a node in a YAML file '
                          'format')
    dump.add_argument('node_name', help='Name of the ROS node')

    load = sub.add_parser('load', help='Load parameter file for a node')
    load.add_argument('node_name', help='Name of the ROS node')
    load.add_argument('parameter_file', help='Parameter file')
    load.add_argument('--no-use-wildcard', action='store_true',
                      help="Do not load parameters in the '/**' namespace into the node")


def main(args: argparse.Namespace) -> int:
    return run_sub_verb(args, args.param_verb, {
        'list': _list, 'get': _get, 'set': _set, 'delete': _delete, 'describe': _describe,
        'dump': _dump, 'load': _load,
    })


def _answer(args: argparse.Namespace, op: str, node: str | None = None, **request: Any) -> Any:
    """The daemon's answer; without a daemon, the node's own through this command's session
    (graph.parameters.answer: the same data either way)."""
    node = args.node_name if node is None else node
    found = ask_daemon(args, op, timeout=_ANSWER_TIMEOUT, name=node, **request)
    if found is not None:
        return found
    from robot_lab.graph.parameters import answer

    return answer(op, {'name': node, **request})


def _list(args: argparse.Namespace) -> int:
    answer = _answer(args, 'param_list', prefixes=args.param_prefixes,
                     include_hidden=args.include_hidden_nodes)
    among, by_node = answer['among'], answer['by_node']
    pattern = re.compile(args.filter[0]) if args.filter else None
    for node in sorted(set(among or by_node)):
        if node not in by_node:  # ros2param's line, on stdout, and on to the next node
            print('Wait for service timed out waiting for parameter services for node '
                  f'{node}')
            continue
        names = by_node[node]
        if pattern is not None:
            names = [n for n in names if pattern.match(n)]
        if not args.node_name and names:
            print(f'{node}:')
        types = {}
        if args.param_type:
            types = {n: _description(args, n, node)['type'] for n in names}
        for name in names:
            print(f'  {name} (type: {types[name]})' if args.param_type else f'  {name}')
    return 0


def _get(args: argparse.Namespace) -> int:
    ptype, value = _answer(args, 'param_get', parameter=args.parameter_name)
    if ptype == 0:
        # ros2param's words and exit status for a parameter the node does not have
        print(value if args.hide_type else 'Parameter not set.')
        print(f'hint: `ros2 param list {args.node_name}` lists the parameters it has',
              file=sys.stderr)
        return 0
    print(value if args.hide_type else f'{_GET_LABELS[ptype]} {value}')
    return 0


def _set(args: argparse.Namespace) -> int:
    (result,) = _answer(args, 'param_set', parameter=args.parameter_name, value=args.value)
    reason = f": {result['reason']}" if result['reason'] else ''
    if result['successful']:
        print('Set parameter successful' + reason)
    else:
        # ros2cli prints the node's reason on stderr and still exits 0
        print('Setting parameter failed' + reason, file=sys.stderr)
    return 0


def _delete(args: argparse.Namespace) -> int:
    result = _answer(args, 'param_delete', parameter=args.parameter_name)
    reason = f": {result['reason']}" if result['reason'] else ''
    if result['successful']:
        print('Deleted parameter successfully' + reason)
    else:  # ros2param: the node's reason on stderr, exit code 0
        print('Deleting parameter failed' + reason, file=sys.stderr)
    return 0


def _description(args: argparse.Namespace, name: str, node: str | None = None) -> Any:
    """One parameter's ParamDescription, as a dict, from the daemon or the node."""
    return _answer(args, 'param_describe', node, parameter=name)


def _describe(args: argparse.Namespace) -> int:
    for name in args.parameter_names:
        d = _description(args, name)
        print('Parameter name:', d['name'])
        print('  Type:', d['type'])
        if d['description']:
            print('  Description:', d['description'])
        print('  Constraints:')
        if d['read_only']:
            print('    Read only: true')
        if d['min_value'] is not None:
            print('    Min value:', d['min_value'])
            print('    Max value:', d['max_value'])
            if d['step']:
                print('    Step:', d['step'])
        if d['additional_constraints']:
            print('    Additional constraints:', d['additional_constraints'])
    return 0


def _dump(args: argparse.Namespace) -> int:
    print(_answer(args, 'param_dump'))
    return 0


def _load(args: argparse.Namespace) -> int:
    from robot_lab.params import load_param_file

    # Read here: a file's errors name it as the user wrote it, and the daemon may run in
    # another folder.
    sections = load_param_file(args.parameter_file)
    use_wildcard = not args.no_use_wildcard
    results = _answer(args, 'param_load', sections=sections, file=args.parameter_file,
                      use_wildcard=use_wildcard)
    for result in results:
        reason = f": {result['reason']}" if result['reason'] else ''
        if result['successful']:
            print(f"Set parameter {result['name']} successful{reason}")
        else:
            print(f"Set parameter {result['name']} failed{reason}", file=sys.stderr)
    return 0
