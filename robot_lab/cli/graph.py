"""`robot-lab graph -o graph.svg|png`: rqt_graph's picture of the running system, as a file."""

from __future__ import annotations

import argparse

HELP = 'Draw the running graph (nodes, topics, publish/subscribe) to an .svg or .png file'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('-o', '--output', default='graph.svg', metavar='FILE',
                        help='picture to write: .svg, .png or .pdf (default: graph.svg)')
    parser.add_argument('-a', '--all', action='store_true',
                        help='include hidden nodes and topics, /rosout and /parameter_events')


def main(args: argparse.Namespace) -> int:
    from robot_lab.graph.view import DEFAULT_HIDDEN_TOPICS, graph_view

    image = graph_view(include_hidden=args.all,
                       hide_topics=() if args.all else DEFAULT_HIDDEN_TOPICS)
    path = image.save(args.output)
    print(f'{path}: {image!r}')
    return 0
