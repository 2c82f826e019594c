"""A picture of the running graph, like rqt_graph: nodes (ellipses), topics (boxes), arrows.

networkx holds the model (node -> topic for a publisher, topic -> node for a subscriber);
matplotlib draws it left to right in layers, so no system graphviz (`dot`) is needed.
`/rosout`, `/parameter_events` and hidden nodes and topics are left out by default, and
names sharing a namespace are framed together.
"""

from __future__ import annotations

import io
import re
import struct
from collections.abc import Iterable
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import TYPE_CHECKING

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import get_session, settled
from robot_lab.graph.nodes import is_hidden, node_list, split_name

if TYPE_CHECKING:
    import networkx as nx
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    from robot_lab.rclpy_session import Session

__all__ = ['DEFAULT_HIDDEN_TOPICS', 'GraphImage', 'graph_model', 'graph_view']

DEFAULT_HIDDEN_TOPICS = ('/rosout', '/parameter_events')

# Drawing sizes in inches (one data unit is one inch, so text and shapes keep proportions).
_FONT = 10
_CHAR = 0.085
_PAD = 0.35
_ROW = 0.75
_BAND_GAP = 0.4
_BOW = 0.6  # how far a back edge's bow may reach out of its row
_GAP = 0.9
_MARGIN = 0.35
_NODE_COLOR = '#dbeafe'
_NODE_EDGE = '#1d4ed8'
_TOPIC_COLOR = '#fef3c7'
_TOPIC_EDGE = '#b45309'
_CLUSTER_COLOR = '#f3f4f6'


def _namespace(name: str) -> str:
    return split_name(name)[1]


def graph_model(include_hidden: bool = False,
                hide_topics: Iterable[str] = DEFAULT_HIDDEN_TOPICS,
                session: Session | None = None) -> nx.DiGraph:
    """The graph as networkx: vertices have `kind` ('node'/'topic'), `namespace`, `types`.

    Edges go node -> topic (publishes) and topic -> node (subscribes), with `kind` set to
    'publish' or 'subscribe'.
    """
    import networkx as nx
    from rclpy.node import NodeNameNonExistentError

    sess = get_session(session)
    hidden_topics = set(hide_topics)

    def probe() -> tuple[list[str], list[tuple[str, str, list[str], str]]]:
        names = node_list(include_hidden=include_hidden, settle=False, session=sess)
        links: list[tuple[str, str, list[str], str]] = []
        for full in names:
            base, namespace = split_name(full)
            for query, kind in ((sess.node.get_publisher_names_and_types_by_node, 'publish'),
                                (sess.node.get_subscriber_names_and_types_by_node,
                                 'subscribe')):
                try:
                    endpoints = query(base, namespace)
                except NodeNameNonExistentError:  # the node left between the queries
                    continue
                links.extend((full, topic, list(types), kind) for topic, types in endpoints
                             if topic not in hidden_topics
                             and (include_hidden or not is_hidden(topic)))
        return names, sorted(links)

    # settle on the whole picture: a fresh session learns nodes before their endpoints
    names, links = settled(sess, probe)
    graph = nx.DiGraph()
    for full in names:
        graph.add_node(full, kind='node', namespace=_namespace(full), types=[])
    for full, topic, types, kind in links:
        vertex = topic if topic not in names else f'{topic} [topic]'
        if vertex not in graph:
            graph.add_node(vertex, kind='topic', namespace=_namespace(topic), types=types,
                           label=topic)
        if kind == 'publish':
            graph.add_edge(full, vertex, kind=kind)
        else:
            graph.add_edge(vertex, full, kind=kind)
    return graph


def _layers(graph: nx.DiGraph) -> dict[str, int]:
    """Longest-path layers after turning back edges of cycles around (like dot's ranking)."""
    order = sorted(graph, key=lambda v: (graph.in_degree(v) > 0, v))
    state: dict[str, int] = {}  # 1 on the DFS stack, 2 done
    forward: list[tuple[str, str]] = []

    def visit(v: str) -> None:
        state[v] = 1
        for w in sorted(graph.successors(v)):
            if state.get(w) == 1:
                continue  # a back edge: it does not push w to the right
            forward.append((v, w))
            if w not in state:
                visit(w)
        state[v] = 2

    for v in order:
        if v not in state:
            visit(v)
    layer = dict.fromkeys(graph, 0)
    changed = True
    while changed:  # forward edges form a DAG, so this settles within |V| rounds
        changed = False
        for v, w in forward:
            if layer[w] < layer[v] + 1:
                layer[w] = layer[v] + 1
                changed = True
    return layer


def _order(graph: nx.DiGraph, layer: dict[str, int]) -> list[list[str]]:
    """Vertices per layer, namespaces kept together, crossings reduced by barycenters."""
    count = max(layer.values(), default=-1) + 1
    rows: list[list[str]] = [sorted(v for v in graph if layer[v] == i) for i in range(count)]
    for sweep in range(6):
        # alternate downward and upward sweeps, each ordering a row by its neighbours' places
        indices = range(1, count) if sweep % 2 == 0 else range(count - 2, -1, -1)
        for i in indices:
            ref = rows[i - 1] if sweep % 2 == 0 else rows[i + 1]
            where = {v: k for k, v in enumerate(ref)}

            def center(v: str, where: dict[str, int] = where) -> float:
                near = [where[u] for u in (*graph.predecessors(v), *graph.successors(v))
                        if u in where]
                return sum(near) / len(near) if near else len(where) / 2

            rows[i].sort(key=lambda v: (graph.nodes[v]['namespace'], center(v)))
    return rows


def _label(graph: nx.DiGraph, vertex: str) -> str:
    return str(graph.nodes[vertex].get('label', vertex))


@dataclass
class _Placed:
    x: float
    y: float
    width: float
    height: float


def _framed_namespaces(graph: nx.DiGraph) -> set[str]:
    """Namespaces (other than the root) with two or more members: they get a frame."""
    count: dict[str, int] = {}
    for _, namespace in graph.nodes(data='namespace'):
        count[namespace] = count.get(namespace, 0) + 1
    return {ns for ns, n in count.items() if ns != '/' and n >= 2}


def _layout_graph(graph: nx.DiGraph) -> tuple[nx.DiGraph, dict[str, int],
                                                dict[tuple[str, str], list[str]]]:
    """The graph plus a dummy vertex per layer an edge skips (dot's trick), so long edges
    get their own lane instead of running through the shapes in between."""
    import networkx as nx

    layer = _layers(graph)
    layout = nx.DiGraph()
    framed = _framed_namespaces(graph)
    for vertex, data in graph.nodes(data=True):
        # a namespace of one is drawn with the root: a band and frame of its own is noise
        layout.add_node(vertex, **{**data, 'namespace': data['namespace']
                                   if data['namespace'] in framed else '/'})
    lanes: dict[tuple[str, str], list[str]] = {}
    for u, v in graph.edges:
        if layer[v] - layer[u] <= 1:
            layout.add_edge(u, v)
            continue
        chain = [f'\0{u}->{v}#{i}' for i in range(layer[u] + 1, layer[v])]
        for i, dummy in enumerate(chain):
            layout.add_node(dummy, kind='lane', namespace=layout.nodes[v]['namespace'])
            layer[dummy] = layer[u] + 1 + i
        nx.add_path(layout, [u, *chain, v])
        lanes[(u, v)] = chain
    return layout, layer, lanes


def _band_order(layout: nx.DiGraph, namespaces: list[str]) -> list[str]:
    """Root band in the middle, the namespaces most linked to it right beside it (alternating
    above and below), so few edges have to cross a frame."""
    links = dict.fromkeys(namespaces, 0)
    for u, v in layout.edges:
        a, b = layout.nodes[u]['namespace'], layout.nodes[v]['namespace']
        if a != b and '/' in (a, b):
            links[b if a == '/' else a] += 1
    others = sorted((ns for ns in namespaces if ns != '/'), key=lambda ns: (-links[ns], ns))
    above, below = others[0::2], others[1::2]
    return [*reversed(above), *(['/'] if '/' in links else []), *below]


def _place(graph: nx.DiGraph) -> tuple[dict[str, _Placed], dict[tuple[str, str], list[str]],
                                       float, float]:
    """Columns are layers; each namespace gets a horizontal band of its own, so its frame
    holds its members only."""
    layout, layer, lanes = _layout_graph(graph)
    rows = _order(layout, layer)
    # band sizes: the most members a namespace has in any one column
    size: dict[str, int] = {}
    for row in rows:
        for namespace in {layout.nodes[v]['namespace'] for v in row}:
            count = sum(1 for v in row if layout.nodes[v]['namespace'] == namespace)
            size[namespace] = max(size.get(namespace, 0), count)
    bands = _band_order(layout, list(size))
    offset: dict[str, float] = {}
    y = 0.0
    for namespace in bands:
        offset[namespace] = y
        y += size[namespace] * _ROW + (_BAND_GAP if namespace != '/' else 0.0)
    height = y + 2 * _MARGIN + 0.2
    placed: dict[str, _Placed] = {}
    x = _MARGIN
    for row in rows:
        widths = [len(_label(layout, v)) * _CHAR + _PAD if layout.nodes[v]['kind'] != 'lane'
                  else 0.0 for v in row]
        column = max(widths, default=1.0)
        for namespace in bands:
            members = [(v, w) for v, w in zip(row, widths, strict=True)
                       if layout.nodes[v]['namespace'] == namespace]
            slack = (size[namespace] - len(members)) * _ROW / 2
            for k, (vertex, width) in enumerate(members):
                top = height - _MARGIN - 0.1 - offset[namespace] - slack - _ROW / 2
                if namespace != '/':
                    top -= _BAND_GAP / 2
                placed[vertex] = _Placed(x + column / 2, top - k * _ROW, width, 0.42)
        x += column + _GAP
    return placed, lanes, max(x - _GAP + _MARGIN, 2.0), max(height, 1.5)


Box = tuple[float, float, float, float]


def _box(spots: list[_Placed]) -> Box:
    return (min(p.x - p.width / 2 for p in spots) - 0.15,
            min(p.y - p.height / 2 for p in spots) - 0.1,
            max(p.x + p.width / 2 for p in spots) + 0.15,
            max(p.y + p.height / 2 for p in spots) + 0.27)


def _inside(spot: _Placed, box: Box) -> bool:
    left, bottom, right, top = box
    return left < spot.x < right and bottom < spot.y < top


def _frames(graph: nx.DiGraph, placed: dict[str, _Placed]) -> list[tuple[str, Box]]:
    """A frame per namespace with two or more members; where one frame would take in a
    stranger, one frame per column instead (members are adjacent within a column)."""
    framed = _framed_namespaces(graph)
    members: dict[str, list[str]] = {}
    for vertex, namespace in graph.nodes(data='namespace'):
        if namespace in framed:
            members.setdefault(namespace, []).append(vertex)
    frames: list[tuple[str, Box]] = []
    for namespace, group in sorted(members.items()):
        box = _box([placed[v] for v in group])
        strangers = [v for v in graph if v not in group and _inside(placed[v], box)]
        if not strangers:
            frames.append((namespace, box))
            continue
        columns: dict[float, list[_Placed]] = {}
        for v in group:
            columns.setdefault(round(placed[v].x, 3), []).append(placed[v])
        frames.extend((namespace, _box(spots)) for _, spots in sorted(columns.items()))
    return frames


def _draw(graph: nx.DiGraph) -> Figure:
    from matplotlib.figure import Figure
    from matplotlib.patches import Ellipse, FancyArrowPatch, FancyBboxPatch, Rectangle

    placed, lanes, width, height = _place(graph)
    # room above or below for the bows of back edges (cycles), on the side they bow to
    back = [placed[u].y for u, v in graph.edges if placed[v].x <= placed[u].x]
    above = _BOW if any(y >= height / 2 for y in back) else 0.0
    below = _BOW if any(y < height / 2 for y in back) else 0.0
    fig = Figure(figsize=(width, height + above + below))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, width)
    ax.set_ylim(-below, height + above)
    ax.set_axis_off()
    if not graph:
        ax.text(width / 2, height / 2, 'no nodes in the graph', ha='center', va='center',
                fontsize=_FONT, color='#6b7280')
        return fig
    for namespace, box in _frames(graph, placed):
        left, bottom, right, top = box
        ax.add_patch(Rectangle((left, bottom), right - left, top - bottom, zorder=0,
                               facecolor=_CLUSTER_COLOR, edgecolor='#9ca3af', linewidth=0.8))
        ax.text(left + 0.06, top - 0.04, namespace, ha='left', va='top', fontsize=_FONT - 2,
                color='#4b5563', zorder=0.5)
    shapes: dict[str, Patch] = {}
    for vertex in graph:
        spot = placed[vertex]
        if graph.nodes[vertex]['kind'] == 'node':
            shape: Patch = Ellipse((spot.x, spot.y), spot.width + 0.2, spot.height + 0.08,
                                 facecolor=_NODE_COLOR, edgecolor=_NODE_EDGE, linewidth=1.2,
                                 zorder=2)
        else:
            shape = FancyBboxPatch((spot.x - spot.width / 2, spot.y - spot.height / 2),
                                   spot.width, spot.height, boxstyle='round,pad=0.02,'
                                   'rounding_size=0.05', facecolor=_TOPIC_COLOR,
                                   edgecolor=_TOPIC_EDGE, linewidth=1.2, zorder=2)
        ax.add_patch(shape)
        shapes[vertex] = shape
        ax.text(spot.x, spot.y, _label(graph, vertex), ha='center', va='center',
                fontsize=_FONT, zorder=3, family='DejaVu Sans')
    for u, v in graph.edges:
        points = [u, *lanes.get((u, v), []), v]
        for a, b in pairwise(points):
            pa, pb = placed[a], placed[b]
            # a cycle's back edge: bow it away from the middle, off the forward edges
            bow = 0.0
            if pb.x <= pa.x:
                span = max(abs(pa.x - pb.x), 0.5)
                bow = min(0.35, 1.6 * _BOW / span) * (1 if pa.y >= height / 2 else -1)
            ax.add_patch(FancyArrowPatch(
                (pa.x, pa.y), (pb.x, pb.y), patchA=shapes.get(a), patchB=shapes.get(b),
                shrinkA=0 if a not in shapes else 2, shrinkB=0 if b not in shapes else 2,
                arrowstyle='-|>' if b == v else '-',
                connectionstyle=f'arc3,rad={bow}', mutation_scale=12, linewidth=1.1,
                color='#374151', zorder=1,
            ))
    return fig


class GraphImage:
    """The graph's picture: shows itself in a notebook and saves to .svg, .png or .pdf."""

    def __init__(self, graph: nx.DiGraph) -> None:
        self.graph = graph
        self._cache: dict[str, bytes] = {}

    def _render(self, fmt: str) -> bytes:
        if fmt not in self._cache:
            from matplotlib.backends.backend_agg import FigureCanvasAgg

            fig = _draw(self.graph)
            FigureCanvasAgg(fig)
            buffer = io.BytesIO()
            fig.savefig(buffer, format=fmt, dpi=110)
            self._cache[fmt] = buffer.getvalue()
        return self._cache[fmt]

    # A notebook output area is about 730 px wide: a wider picture is shown scaled down to
    # this width instead of needing a sideways scroll.
    DISPLAY_WIDTH = 720

    def _display_metadata(self) -> dict[str, int]:
        png = self._render('png')
        width, height = struct.unpack('>II', png[16:24])  # the PNG IHDR chunk
        if width <= self.DISPLAY_WIDTH:
            return {'width': width, 'height': height}
        return {'width': self.DISPLAY_WIDTH, 'height': round(height * self.DISPLAY_WIDTH / width)}

    def _repr_png_(self) -> tuple[bytes, dict[str, int]]:
        return self._render('png'), self._display_metadata()

    def _repr_svg_(self) -> tuple[str, dict[str, int]]:
        # JupyterLab draws an SVG at the size its root element names and ignores the width
        # in the metadata (measured in Chromium: 1,038-1,323 px in a 912 px column): the
        # root says the display size itself; the viewBox keeps the drawing whole.
        size = self._display_metadata()
        svg = re.sub(r'(<svg\b[^>]*?)\swidth="[^"]*"\s+height="[^"]*"',
                     lambda m: f'{m.group(1)} width="{size["width"]}px" '
                               f'height="{size["height"]}px"',
                     self._render('svg').decode(), count=1)
        return svg, size

    def save(self, path: str | Path) -> Path:
        """Write the picture; the format comes from the suffix (.svg, .png, .pdf)."""
        target = Path(path)
        fmt = target.suffix.lstrip('.').lower()
        if fmt not in ('svg', 'png', 'pdf'):
            raise GraphError(f"cannot save a graph picture as '{target.suffix}'",
                             fix='use a file name ending in .svg, .png or .pdf')
        target.write_bytes(self._render(fmt))
        return target

    def __repr__(self) -> str:
        nodes = sum(1 for _, k in self.graph.nodes(data='kind') if k == 'node')
        topics = self.graph.number_of_nodes() - nodes
        return f'<GraphImage: {nodes} nodes, {topics} topics, {self.graph.number_of_edges()} edges>'


def graph_view(include_hidden: bool = False,
               hide_topics: Iterable[str] = DEFAULT_HIDDEN_TOPICS,
               session: Session | None = None) -> GraphImage:
    """The running graph as a picture (`robot_lab.graph_view()` in a notebook cell)."""
    return GraphImage(graph_model(include_hidden, hide_topics, session=session))
