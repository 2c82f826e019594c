"""`ros2 run tf2_tools view_frames`: listen to /tf for a while, write `frames_<date>.gv` (the
text geometry2's view_frames.py writes) and `frames_<date>.pdf` — drawn here with
matplotlib, as a tree top-down, so no Graphviz binary is needed — and, in a notebook,
`frames_figure()` gives the same picture inline.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml

__all__ = ['draw_frames', 'frames_figure', 'generate_dot', 'main', 'tree_layout', 'view_frames']


def generate_dot(data: Mapping[str, Any] | Sequence[Any], recorded_time: tuple[int, int]) -> str:
    """The .gv text of upstream's generate_dot (from the buffer's YAML as a dict)."""
    if len(data) == 0 or not isinstance(data, Mapping):
        return 'digraph G { "No tf data received" }'
    dot = 'digraph G {\n'
    root = ''
    for el, info in data.items():
        dot += f'"{info["parent"]}" -> "{el}"[label=" '
        dot += f'Broadcaster: {info["broadcaster"]}\\n'
        dot += f'Average rate: {info["rate"]}\\n'
        dot += f'Buffer length: {info["buffer_length"]}\\n'
        dot += f'Most recent transform: {info["most_recent_transform"]}\\n'
        dot += f'Oldest transform: {info["oldest_transform"]}\\n'
        dot += '"];\n'
        if info['parent'] not in data:
            root = info['parent']
    dot += 'edge [style=invis];\n'
    dot += ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";\n'
    dot += (f'"Recorded at time: {recorded_time[0] + recorded_time[1] / 1e9}"'
            '[ shape=plaintext ] ;\n')
    dot += f'}}->"{root}";\n}}'
    return dot


def tree_layout(data: Mapping[str, Any]) -> dict[str, tuple[float, float]]:
    """Positions for a top-down tree: depth down the page, leaves spread left to right."""
    children: dict[str, list[str]] = {}
    for child, info in data.items():
        children.setdefault(str(info['parent']), []).append(str(child))
    roots = sorted({str(info['parent']) for info in data.values()} - {str(c) for c in data})
    pos: dict[str, tuple[float, float]] = {}
    next_x = [0.0]

    def place(name: str, depth: int, seen: frozenset[str]) -> float:
        kids = [k for k in sorted(children.get(name, [])) if k not in seen]
        if not kids:
            x = next_x[0]
            next_x[0] += 1.8  # room for the edge labels beside each branch
        else:
            xs = [place(k, depth + 1, seen | {k}) for k in kids]
            x = (xs[0] + xs[-1]) / 2.0
        pos[name] = (x, -float(depth))
        return x

    for root in roots or sorted(children)[:1]:
        place(root, 0, frozenset({root}))
    return pos


def draw_frames(data: Mapping[str, Any] | Sequence[Any], recorded_time: tuple[int, int],
                ax: Any = None) -> Any:
    """The frame tree on matplotlib axes: frames as ellipses, edges labelled as view_frames."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Ellipse

    if ax is None:  # a Figure of its own, not pyplot's: a notebook shows it once
        width = 8.27 if not isinstance(data, Mapping) else max(8.27, 1.6 * len(data))
        ax = Figure(figsize=(width, 5.8)).subplots()
    ax.set_axis_off()
    stamp = recorded_time[0] + recorded_time[1] / 1e9
    if not data or not isinstance(data, Mapping):
        ax.text(0.5, 0.5, 'No tf data received', ha='center', va='center',
                transform=ax.transAxes)
        return ax.figure
    pos = tree_layout(data)
    for child, info in data.items():
        (x0, y0), (x1, y1) = pos[str(info['parent'])], pos[str(child)]
        ax.annotate('', xy=(x1, y1 + 0.12), xytext=(x0, y0 - 0.12),
                    arrowprops={'arrowstyle': '->', 'color': '0.3'})
        ax.text(x0 + 0.6 * (x1 - x0) + 0.08, y0 + 0.6 * (y1 - y0),
                f'Broadcaster: {info["broadcaster"]}\nAverage rate: {info["rate"]}\n'
                f'Buffer length: {info["buffer_length"]}\n'
                f'Most recent transform: {info["most_recent_transform"]}\n'
                f'Oldest transform: {info["oldest_transform"]}',
                fontsize=6, va='center', ha='left', color='0.25')
    for name, (x, y) in pos.items():
        ax.add_patch(Ellipse((x, y), 0.8, 0.24, facecolor='white', edgecolor='black'))
        ax.text(x, y, name, ha='center', va='center', fontsize=9)
    xs = [p[0] for p in pos.values()]
    ys = [p[1] for p in pos.values()]
    ax.set_xlim(min(xs) - 0.6, max(xs) + 1.4)
    ax.set_ylim(min(ys) - 0.5, max(ys) + 0.6)
    ax.set_title(f'view_frames Result\nRecorded at time: {stamp}', fontsize=9)
    return ax.figure


def frames_figure(buffer_or_yaml: Any, recorded_time: tuple[int, int] | None = None) -> Any:
    """The view_frames picture of a tf2_ros Buffer (or its all_frames_as_yaml text), for a
    notebook cell to show inline."""
    text = (buffer_or_yaml if isinstance(buffer_or_yaml, str)
            else buffer_or_yaml.all_frames_as_yaml())
    now = time.time_ns()
    return draw_frames(yaml.safe_load(text) or {}, recorded_time or (now // 10**9,
                                                                     now % 10**9))


def view_frames(wait_time: float = 5.0) -> Any:
    """In a notebook: listen to /tf and /tf_static for `wait_time` s (as the program does)
    on the kernel's session, and return the picture of the tree, shown inline."""
    import rclpy

    from robot_lab.rclpy_session import session
    from robot_lab.tf2.buffer import Buffer
    from robot_lab.tf2.listener import TransformListener

    sess = session()
    node = rclpy.create_node(f'view_frames_{time.monotonic_ns()}', context=sess.context)
    buffer = Buffer()
    listener = TransformListener(buffer, node)
    sess.add_node(node)
    try:
        time.sleep(wait_time)  # the listening window itself, as `view_frames -t`
    finally:
        listener.unregister()
        sess.remove_node(node)
        node.destroy_node()
    return frames_figure(buffer)


def main(argv: Sequence[str] | None = None) -> int:
    """The view_frames program."""
    import matplotlib
    matplotlib.use('Agg')
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.utilities import remove_ros_args
    from tf2_msgs.srv import FrameGraph

    from robot_lab.tf2.buffer import Buffer
    from robot_lab.tf2.listener import TransformListener
    from robot_lab.tf2.static_publisher import version_line

    full = list(sys.argv if argv is None else argv)
    args = remove_ros_args(full)
    if '--version' in args[1:]:
        print(version_line('view_frames'))
        return 0
    parser = argparse.ArgumentParser(
        description='Create a diagram of the TF frames being broadcast over ROS')
    parser.add_argument('--wait-time', '-t', type=float, default=5.0,
                        help='Listen to the /tf topic for this many seconds before rendering '
                             'the frame tree')
    parser.add_argument('-o', '--output', help='Output filename')
    parsed = parser.parse_args(args[1:])
    rclpy.init(args=full)
    node = rclpy.create_node('view_frames')
    try:
        buf = Buffer(node=node)
        TransformListener(buf, node, spin_thread=False)
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        log = node.get_logger()
        log.info(f'Listening to tf data for {parsed.wait_time} seconds...')
        start = time.time()
        while time.time() - start < parsed.wait_time:
            executor.spin_once(timeout_sec=0.1)
        log.info('Generating graph...')
        result = FrameGraph.Response(frame_yaml=buf.all_frames_as_yaml())
        log.info('Result:' + str(result))
        data = yaml.safe_load(result.frame_yaml) or {}
        if parsed.output is not None:
            frames_gv, frames_pdf = f'{parsed.output}.gv', f'{parsed.output}.pdf'
        else:
            stamp = time.strftime('%Y-%m-%d_%H.%M.%S')
            frames_gv, frames_pdf = f'frames_{stamp}.gv', f'frames_{stamp}.pdf'
        log.info(f'Exporting graph in {frames_pdf} file...')
        recorded = node.get_clock().now().seconds_nanoseconds()
        Path(frames_gv).write_text(generate_dot(data, recorded))
        figure = draw_frames(data, recorded)
        figure.savefig(frames_pdf)
        return 0
    finally:
        node.destroy_node()
        rclpy.utilities.try_shutdown()


def program() -> None:
    sys.exit(main())
