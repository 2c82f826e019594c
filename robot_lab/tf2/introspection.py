"""The buffer as Graphviz text (BufferCore::_allFramesAsDot), what view_frames draws."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robot_lab.tf2.time_cache import display, seconds

if TYPE_CHECKING:
    from robot_lab.tf2.buffer_core import BufferCore


def frames_as_dot(core: BufferCore, current_time: int = 0) -> str:
    """`digraph G { "parent" -> "child"[label="Broadcaster: ..."]; ... }` as tf2 writes it."""
    out = ['digraph G {\n']
    frames = core.frames()
    if not frames:
        out.append('"no tf data recieved"')
    for name, cache in frames:
        latest = cache.get_data(0) if cache is not None else None
        if cache is None or latest is None:
            continue
        newest, oldest = cache.latest_stamp(), cache.oldest_stamp()
        rate = len(cache) * 1e9 / max(newest - oldest, 100_000)
        out.append(f'"{core.parent_name(latest.frame_id)}" -> "{name}"[label="'
                   f'Broadcaster: {core.authority(name)}\\n'
                   f'Average rate: {rate:.3f} Hz\\n'
                   f'Most recent transform: {display(newest)} ')
        if current_time:
            out.append(f'( {seconds(current_time - newest):.3f} sec old)')
        out.append(f'\\nBuffer length: {seconds(newest - oldest):.3f} sec\\n"];\n')
    legend = ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";\n'
    recorded = (f'"Recorded at time: {display(current_time)}"[ shape=plaintext ] ;\n '
                if current_time else '')
    for name, cache in frames:
        if cache is None:
            if current_time:
                out.append(f'edge [style=invis];\n{legend}{recorded}}}->"{name}";\n')
            continue
        latest = cache.get_data(0)
        parent = latest.frame_id if latest is not None else 0
        if core.parent_name(parent) == 'NO_PARENT':
            out.append(f'edge [style=invis];\n{legend}{recorded}}}->"{name}";\n')
    out.append('}')
    return ''.join(out)
