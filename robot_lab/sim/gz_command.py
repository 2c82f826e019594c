"""`gz`, the venv's stand-in for Gazebo's command line: `sim`, `topic`, `service`.

The Jazzy tutorials type `gz sim -v 4 -r visualize_lidar.sdf`, `gz topic -l`,
`gz topic -e -t /scan`, `gz topic -t /cmd_vel -m gz.msgs.Twist -p 'linear: {x: 0.5}'` and
`gz service -s /world/<name>/control --reqtype gz.msgs.WorldControl ... --req 'pause: true'`
(and `/world/<name>/create` with a gz.msgs.EntityFactory, as Gazebo's spawn tutorial).
Each does the same against robot_lab's simulator of this partition; messages print as
protobuf text format (`key: value`, nested `key { ... }`), as gz does.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from collections.abc import Sequence
from typing import Any

from robot_lab.errors import RobotLabError

__all__ = ['main', 'parse_text_format', 'text_format']

_TOKEN = re.compile(r'\s*(?:([A-Za-z_][\w.]*)|(-?[\d.]+(?:[eE][-+]?\d+)?)|("(?:[^"\\]|\\.)*")'
                    r'|([:{},;]))')
_ESCAPES = {'n': '\n', 't': '\t'}


def parse_text_format(text: str) -> dict[str, Any]:
    """Protobuf text format (`linear: {x: 0.5} angular {z: 0.2}`) -> a dict."""
    tokens: list[str] = []
    position = 0
    text = text.strip()
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None or match.end() == position:
            raise RobotLabError(f'cannot read {text[position:]!r} as protobuf text format',
                                fix="write it as 'linear: {x: 0.5}, angular: {z: 0.2}'")
        tokens.append(match.group(0).strip())
        position = match.end()
    stream = iter([*tokens, '}'])

    def value(token: str) -> Any:
        if token == '{':
            return fields()
        if token.startswith('"'):  # protobuf's escapes: \" \\ \n \t
            return re.sub(r'\\(.)', lambda m: _ESCAPES.get(m[1], m[1]), token[1:-1])
        if token in ('true', 'false'):
            return token == 'true'
        try:
            return float(token) if any(c in token for c in '.eE') else int(token)
        except ValueError:
            return token  # an enum's name

    def fields() -> dict[str, Any]:
        out: dict[str, Any] = {}
        for token in stream:
            if token in (',', ';'):
                continue
            if token == '}':
                return out
            following = next(stream)
            if following == ':':
                following = next(stream)
            out[token] = value(following)
        return out

    return fields()


def text_format(message: dict[str, Any], indent: str = '') -> str:
    """A message dict as gz prints it."""
    lines = []
    for key, item in message.items():
        for one in item if isinstance(item, list) else [item]:
            if isinstance(one, dict):
                lines.append(f'{indent}{key} {{\n{text_format(one, indent + "  ")}{indent}}}')
            elif isinstance(one, str):
                lines.append(f'{indent}{key}: "{one}"')
            elif isinstance(one, bool):
                lines.append(f'{indent}{key}: {str(one).lower()}')
            else:
                lines.append(f'{indent}{key}: {one}')
    return ''.join(line + '\n' for line in lines)


def _topic(argv: Sequence[str]) -> int:
    from robot_lab.sim.control import gz_topics
    from robot_lab.sim.transport import connect

    parser = argparse.ArgumentParser(prog='gz topic')
    parser.add_argument('-l', '--list', action='store_true')
    parser.add_argument('-e', '--echo', action='store_true')
    parser.add_argument('-i', '--info', action='store_true')
    parser.add_argument('-t', '--topic', default='')
    parser.add_argument('-m', '--msgtype', default='')
    parser.add_argument('-p', '--pub', default=None)
    parser.add_argument('-n', '--num', type=int, default=0)
    args = parser.parse_args(argv)
    if args.list:
        print('\n'.join(sorted(gz_topics())))
        return 0
    if args.info:
        kind = gz_topics().get(args.topic)
        print(f'Publishers [Address, Message Type]:\n  robot_lab, {kind}' if kind else
              'No publishers on topic ' + args.topic)
        return 0
    connection = connect()
    if connection is None:
        print('no simulation runs in this partition', file=sys.stderr)
        return 1
    if args.pub is not None:
        connection.send({'op': 'pub', 'topic': args.topic, 'type': args.msgtype,
                         'msg': parse_text_format(args.pub)})
        connection.close()
        return 0
    if args.echo:
        connection.send({'op': 'sub', 'topic': args.topic})
        count = 0
        try:
            while (frame := connection.receive()) is not None:
                print(text_format(frame['msg']), flush=True)
                count += 1
                if args.num and count >= args.num:
                    break
        except KeyboardInterrupt:
            pass
        connection.close()
        return 0
    parser.print_usage()
    return 1


def _service(argv: Sequence[str]) -> int:
    from robot_lab.sim.control import world_control
    from robot_lab.sim.conversions import control_fields

    parser = argparse.ArgumentParser(prog='gz service')
    parser.add_argument('-s', '--service', required=True)
    parser.add_argument('--reqtype', default='gz.msgs.WorldControl')
    parser.add_argument('--reptype', default='gz.msgs.Boolean')
    parser.add_argument('--timeout', type=int, default=1000)
    parser.add_argument('-r', '--req', default='')
    args = parser.parse_args(argv)
    if re.fullmatch(r'/world/[^/]+/create', args.service):
        return _create(args.service.split('/')[2], parse_text_format(args.req))
    if not re.fullmatch(r'/world/[^/]+/control', args.service):
        print(f"robot_lab's simulator offers /world/<name>/control and /world/<name>/create "
              f'only, not {args.service}', file=sys.stderr)
        return 1
    request = parse_text_format(args.req)
    reset = request.get('reset', {})
    target = request.get('run_to_sim_time', {})
    frame, unsupported = control_fields(
        bool(request.get('pause', False)), int(request.get('multi_step', 0)),
        bool(request.get('step', False)), reset if isinstance(reset, dict) else {},
        int(request.get('seed', 0)),
        int(target.get('sec', 0)) * 1_000_000_000 + int(target.get('nsec', 0)))
    unknown = [k for k in request if k not in ('pause', 'step', 'multi_step', 'reset', 'seed',
                                               'run_to_sim_time')]
    if unsupported:
        print(f"gz service: {', '.join(unsupported)}: Gazebo does not honour it either; "
              f'ignored', file=sys.stderr)
    if unknown:
        print(f"gz service: {', '.join(unknown)}: not a gz.msgs.WorldControl field; ignored",
              file=sys.stderr)
    world_control(pause=frame['pause'], step=frame['multi_step'], reset=frame['reset'],
                  world=args.service.split('/')[2],
                  run_to=frame.get('run_to_sim_time', 0) / 1e9)
    print('data: true\n')
    return 0


def _rpy(q: dict[str, Any]) -> list[float]:
    """Roll, pitch, yaw of a gz.msgs.Quaternion (absent: the identity)."""
    x, y, z, w = (float(q.get(k, 1.0 if k == 'w' else 0.0)) for k in 'xyzw')
    return [math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
            math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x)))),
            math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))]


def _create(world: str, request: dict[str, Any]) -> int:
    """gz.msgs.EntityFactory on /world/<name>/create, as Gazebo's spawn tutorial sends it
    (`sdf_filename` or `sdf`, `name`, `allow_renaming`, `pose`); prints the gz.msgs.Boolean."""
    from pathlib import Path

    from robot_lab.sim.transport import connect

    unsupported = [k for k in request
                   if k not in ('sdf', 'sdf_filename', 'name', 'allow_renaming', 'pose')]
    if unsupported:
        print(f"gz service: {', '.join(unsupported)} not supported by robot_lab's simulator "
              f'(sdf, sdf_filename, name, allow_renaming and pose are); ignored',
              file=sys.stderr)
    filename = str(request.get('sdf_filename', ''))
    text = Path(filename).expanduser().read_text() if filename else str(request.get('sdf', ''))
    pose = request.get('pose', {})
    position = pose.get('position', {})
    connection = connect()
    if connection is None:
        print('no simulation runs in this partition', file=sys.stderr)
        return 1
    name = str(request.get('name', ''))
    for attempt in range(100 if request.get('allow_renaming') and name else 1):
        connection.send({'op': 'create', 'id': attempt + 1, 'urdf': text,
                         'name': name if attempt == 0 else f'{name}_{attempt}',
                         'source': filename or 'robot_description', 'world': world,
                         'xyz': [float(position.get(k, 0.0)) for k in 'xyz'],
                         'rpy': _rpy(pose.get('orientation', {}))})
        reply = connection.receive() or {}
        if reply.get('ok') or 'already exists' not in str(reply.get('error', '')):
            break
    connection.close()
    if not reply.get('ok'):
        print(reply.get('error', 'the simulation closed the connection'), file=sys.stderr)
    print(f"data: {'true' if reply.get('ok') else 'false'}\n")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    from robot_lab.sim.about import identity

    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ('--version', '-v', 'help', '--help', '-h'):
        print(identity())
        print('commands: gz sim [-r] [-s] [-v N] WORLD.sdf | gz topic -l|-e|-i|-p | '
              'gz service -s /world/<name>/control|create --req ...')
        return 0
    command, rest = args[0], args[1:]
    try:
        if command == 'sim':
            from robot_lab.sim.server import main as sim_main

            return sim_main(rest)
        if command == 'topic':
            return _topic(rest)
        if command == 'service':
            return _service(rest)
    except RobotLabError as error:
        print(error, file=sys.stderr)
        return 1
    print(f'gz {command}: not available in robot_lab (sim, topic and service are)',
          file=sys.stderr)
    return 1


if __name__ == '__main__':
    sys.exit(main())
