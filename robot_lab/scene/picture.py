"""The 3D view where no browser draws it (nbval, CI, a static page): a matplotlib picture.

It shows what the view knows without three.js: each TF frame's origin and name, a line to
its parent, and the view's status lines as the title, so a saved notebook still says which
frames there were and what was missing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from robot_lab.scene.frames import Pose

__all__ = ['frames_picture']


def frames_picture(fixed: str, poses: dict[str, Pose | None], tree: list[tuple[str, str]],
                   lines: list[str]) -> Figure:
    """The TF frames (axes and names) seen in 3D, with the status lines as a title."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.0, 4.5), dpi=100)
    ax = fig.add_subplot(projection='3d')
    shown = {k: v for k, v in poses.items() if v is not None}
    for child, parent in tree:
        a, b = shown.get(child), shown.get(parent)
        if a is not None and b is not None:
            ax.plot([a[0], b[0]], [a[1], b[1]], [a[2], b[2]], color='#c8a000', lw=1)
    for name, p in shown.items():
        ax.scatter([p[0]], [p[1]], [p[2]], color='#0072B2', s=12)
        ax.text(p[0], p[1], p[2], ' ' + name, fontsize=7)
    xs = [p[0] for p in shown.values()] or [0.0]
    ys = [p[1] for p in shown.values()] or [0.0]
    zs = [p[2] for p in shown.values()] or [0.0]
    span = max(max(xs) - min(xs), max(ys) - min(ys), max(zs) - min(zs), 0.5) / 2 + 0.1
    for setter, values in ((ax.set_xlim, xs), (ax.set_ylim, ys), (ax.set_zlim, zs)):
        mid = (max(values) + min(values)) / 2
        setter(mid - span, mid + span)
    ax.set_xlabel('x (m)', fontsize=8)
    ax.set_ylabel('y (m)', fontsize=8)
    ax.set_title(f'TF frames in [{fixed or "?"}]\n' + '\n'.join(
        line[:90] for line in lines[:3]), fontsize=8, loc='left')
    fig.tight_layout()
    return fig
