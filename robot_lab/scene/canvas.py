"""The 3D view's widget: anywidget running the committed bundle `data/scene_view.js`.

The bundle is three.js and urdf-loader from npm, built by `js/scene_view/build.mjs`
(esbuild, minified); the kit ships the built file, so installing robot_lab needs no node,
and the page loads nothing from a CDN. Its state is what a user may change from either side:
the fixed frame, the hidden TF frames; `status` is the line under the picture; `camera` is
where `SceneView.look_at` put the eye and the orbit's centre (a page drawn again, or
reloaded, starts there too).
"""

from __future__ import annotations

from pathlib import Path

import anywidget
import traitlets

__all__ = ['BUNDLE', 'SceneCanvas']

BUNDLE = Path(__file__).resolve().parents[1] / 'data' / 'scene_view.js'


class SceneCanvas(anywidget.AnyWidget):
    """The browser side of `SceneView`; fed by the view's own thread."""

    _esm = BUNDLE.read_text(encoding='utf-8')
    height = traitlets.Int(480).tag(sync=True)
    fixed_frame = traitlets.Unicode('').tag(sync=True)
    hidden_frames = traitlets.List(traitlets.Unicode()).tag(sync=True)
    status = traitlets.List(traitlets.Unicode()).tag(sync=True)
    # eye x, y, z, then target x, y, z in the fixed frame; empty: the bundle's own camera
    camera = traitlets.List(traitlets.Float()).tag(sync=True)
