"""`robot-lab` and the venv's `ros2`: one dispatcher, one module per verb.

A verb module defines `HELP`, `add_arguments(parser)` and `main(args) -> int`; it prints
only, its data comes from the library (robot_lab.graph, robot_lab.launch, ...). Verb
modules import rclpy lazily, so `--help` and errors stay fast.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
from collections.abc import Callable, Mapping, Sequence
from types import ModuleType

from robot_lab import __version__
from robot_lab.errors import RobotLabError
from robot_lab.rclpy_session import defer_code_generator

__all__ = ['main', 'ros2_main', 'run_sub_verb']

# verb -> module under robot_lab.cli (the order is the order of `--help`)
VERBS: dict[str, str] = {
    'run': 'run',
    'launch': 'launch',
    'node': 'node',
    'topic': 'topic',
    'param': 'param',
    'service': 'service',
    'action': 'action',
    'lifecycle': 'lifecycle',
    'interface': 'interface',
    'graph': 'graph',
    'pkg': 'pkg',
    'build': 'build',
    'doctor': 'doctor',
    'bag': 'bag',
    'daemon': 'daemon',
    'demo': 'demo',
    'exercises': 'exercises',
    'course': 'course',
    'grade': 'grade',
    'domain': 'domain',
}


def _verb_module(verb: str) -> ModuleType | None:
    try:
        return importlib.import_module(f'robot_lab.cli.{VERBS[verb]}')
    except ModuleNotFoundError as exc:
        if exc.name == f'robot_lab.cli.{VERBS[verb]}':
            return None  # verb not built yet
        raise


def _parser(prog: str, only: str | None = None) -> argparse.ArgumentParser:
    """The whole command line, or with `only` just that verb's part: every verb module
    imported and built costs ~60 ms, which a launcher pays before its first node starts."""
    parser = argparse.ArgumentParser(
        prog=prog,
        description='robot_lab: ROS 2 Jazzy tools for the course kit (no ROS install needed).',
    )
    parser.add_argument(
        '--version', action='version',
        version=f'{prog} (robot_lab {__version__}: ROS 2 Jazzy from PyPI wheels; '
        'launch and ros2cli verbs provided by robot_lab, not a full ROS 2 install)',
    )
    sub = parser.add_subparsers(dest='verb', metavar='VERB')
    for verb in VERBS if only is None else [only]:
        module = _verb_module(verb)
        if module is None:
            continue
        verb_parser = sub.add_parser(verb, help=module.HELP, description=module.HELP)
        module.add_arguments(verb_parser)
        # `args._parser`: a verb with sub-verbs prints its own help when given none.
        verb_parser.set_defaults(_main=module.main, _parser=verb_parser)
    return parser


def run_sub_verb(args: argparse.Namespace, chosen: str | None,
                 verbs: Mapping[str, Callable[[argparse.Namespace], int]]) -> int:
    """Run the sub-verb (`topic list`, `bag info`, ...) the command line chose; given none,
    print the verb's help and succeed, as ros2cli does."""
    verb = verbs.get(chosen or '')
    if verb is None:
        args._parser.print_help()
        return 0
    return verb(args)


def print_names(found: Sequence[tuple[str, Sequence[str]]], *, count: bool,
                show_types: bool) -> None:
    """`topic|service|action list`'s output: a count (`-c`), or a name per line, with its
    types in brackets under `-t`."""
    if count:
        print(len(found))
        return
    for name, types in found:
        print(f'{name} [{", ".join(types)}]' if show_types else name)


def main(argv: Sequence[str] | None = None, prog: str = 'robot-lab') -> int:
    # rclpy's parameter services import numpy, whose OpenBLAS pool spins a thread for
    # ~80 ms of CPU at start-up: a one-shot command (and the daemon and nodes it may start)
    # has no use for it. A value the user set wins.
    os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
    _take_sigint_back()
    defer_code_generator()
    words = list(sys.argv[1:] if argv is None else argv)
    parser = _parser(prog, only=words[0] if words and words[0] in VERBS else None)
    args = parser.parse_args(words)
    if args.verb is None:
        parser.print_help()
        return 0
    try:
        code: int = args._main(args)
    except RobotLabError as err:
        print(str(err), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    return code


def _take_sigint_back() -> None:
    """Ctrl-C (SIGINT) stops a command even where it started ignored, as in ros2cli.

    bash starts a script's background jobs with SIGINT ignored, and an ignored signal stays
    ignored across exec. ros2cli's verbs take it back in rclpy.init; the kit's must too, or
    a cell's `ros2 topic echo … &` then `kill -INT %1; wait` hangs for ever. `ros2 run`
    hands it on to the node's program, so a kill also stops the package's first build and
    a node still importing (lesson 10's first cell hung that way, while turtlesim built).
    """
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def ros2_main(argv: Sequence[str] | None = None) -> int:
    """`ros2 …` inside the kit's venv: the same verbs, so the labs' commands work as written."""
    return main(argv, prog='ros2')


def _exit_quietly_on_closed_stdout(run: Callable[[], int]) -> None:
    """`ros2 interface list | head`: the reader went away, so stop without a traceback.

    stdout is pointed at /dev/null so the interpreter's final flush cannot fail again;
    the exit code is the shell's for a process ended by SIGPIPE (128 + 13).
    """
    try:
        code = run()
        sys.stdout.flush()
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        sys.exit(141)
    sys.exit(code)


def entry() -> None:
    _exit_quietly_on_closed_stdout(main)


def ros2_entry() -> None:
    _exit_quietly_on_closed_stdout(ros2_main)
