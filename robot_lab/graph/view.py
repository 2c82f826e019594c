"""A picture of the running graph, like rqt_graph: nodes (ellipses), topics (boxes), arrows.

networkx holds the model (node -> topic for a publisher, topic -> node for a subscriber);
matplotlib draws it left to right in layers, so no system graphviz (`dot`) is needed.
`/rosout`, `/parameter_events` and hidden nodes and topics are left out by default, and
names sharing a namespace are framed together.
"""

from __future__ import annotations

import io
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robot_lab.errors import GraphError
from robot_lab.graph.discovery import get_session
from robot_lab.graph.nodes import is_hidden, node_list, split_name

if TYPE_CHECKING:
    import networkx as nx

    from robot_lab.context import Session

__all__ = ['DEFAULT_HIDDEN_TOPICS', 'GraphImage', 'graph_model', 'graph_view']

DEFAULT_HIDDEN_TOPICS = ('/rosout', '/parameter_events')

# Drawing sizes in inches (one data unit is one inch, so text and shapes keep proportions).
_FONT = 10
_CHAR = 0.085
_PAD = 0.35
_ROW = 0.75
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

    sess = get_session(session)
    hidden_topics = set(hide_topics)
    graph = nx.DiGraph()
    names = node_list(include_hidden=include_hidden, session=sess)
    for full in names:
        graph.add_node(full, kind='node', namespace=_namespace(full), types=[])
    for full in names:
        base, namespace = split_name(full)
        for query, kind in ((sess.node.get_publisher_names_and_types_by_node, 'publish'),
                            (sess.node.get_subscriber_names_and_types_by_node, 'subscribe')):
            try:
                endpoints = query(base, namespace)
            except Exception:  # the node left between the two queries: skip it
                continue
            for topic, types in endpoints:
                if topic in hidden_topics or (is_hidden(topic) and not include_hidden):
                    continue
                vertex = topic if topic not in names else f'{topic} [topic]'
                if vertex not in graph:
                    graph.add_node(vertex, kind='topic', namespace=_namespace(topic),
                                   types=list(types), label=topic)
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
    for _ in range(4):
        for i in range(1, count):
            where = {v: k for k, v in enumerate(rows[i - 1])}

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


def _place(graph: nx.DiGraph) -> tuple[dict[str, _Placed], float, float]:
    rows = _order(graph, _layers(graph))
    placed: dict[str, _Placed] = {}
    x = _MARGIN
    tallest = max((len(r) for r in rows), default=1)
    height = tallest * _ROW + 2 * _MARGIN + 0.3
    for row in rows:
        widths = [len(_label(graph, v)) * _CHAR + _PAD for v in row]
        column = max(widths, default=1.0)
        top = height / 2 + (len(row) - 1) * _ROW / 2
        for k, (vertex, width) in enumerate(zip(row, widths, strict=True)):
            placed[vertex] = _Placed(x + column / 2, top - k * _ROW, width, 0.42)
        x += column + _GAP
    return placed, max(x - _GAP + _MARGIN, 2.0), max(height, 1.5)


def _draw(graph: nx.DiGraph) -> Any:
    from matplotlib.figure import Figure
    from matplotlib.patches import Ellipse, FancyArrowPatch, FancyBboxPatch, Rectangle

    placed, width, height = _place(graph)
    fig = Figure(figsize=(width, height))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.set_axis_off()
    if not placed:
        ax.text(width / 2, height / 2, 'no nodes in the graph', ha='center', va='center',
                fontsize=_FONT, color='#6b7280')
        return fig
    # namespace frames first, so they sit behind everything
    members: dict[str, list[str]] = {}
    for vertex, data in graph.nodes(data=True):
        if data['namespace'] != '/':
            members.setdefault(data['namespace'], []).append(vertex)
    for namespace, group in sorted(members.items()):
        if len(group) < 2:
            continue
        left = min(placed[v].x - placed[v].width / 2 for v in group) - 0.12
        right = max(placed[v].x + placed[v].width / 2 for v in group) + 0.12
        bottom = min(placed[v].y - placed[v].height / 2 for v in group) - 0.12
        top = max(placed[v].y + placed[v].height / 2 for v in group) + 0.28
        ax.add_patch(Rectangle((left, bottom), right - left, top - bottom, zorder=0,
                               facecolor=_CLUSTER_COLOR, edgecolor='#9ca3af', linewidth=0.8))
        ax.text(left + 0.06, top - 0.05, namespace, ha='left', va='top', fontsize=_FONT - 2,
                color='#4b5563', zorder=0.5)
    shapes: dict[str, Any] = {}
    for vertex, spot in placed.items():
        if graph.nodes[vertex]['kind'] == 'node':
            shape: Any = Ellipse((spot.x, spot.y), spot.width + 0.2, spot.height + 0.08,
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
        a, b = placed[u], placed[v]
        backwards = b.x <= a.x  # a cycle's back edge: bend it so it does not hide another
        ax.add_patch(FancyArrowPatch(
            (a.x, a.y), (b.x, b.y), patchA=shapes[u], patchB=shapes[v],
            arrowstyle='-|>', mutation_scale=12, linewidth=1.1, color='#374151',
            connectionstyle=f'arc3,rad={0.35 if backwards else 0.0}', zorder=1,
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

    def _repr_png_(self) -> bytes:
        return self._render('png')

    def _repr_svg_(self) -> str:
        return self._render('svg').decode()

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
