"""The graph picture: the networkx model of the real system, and the files it writes."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import Proc, reference_system, run_cli

import robot_lab
from robot_lab import GraphError
from robot_lab.graph.view import GraphImage, graph_model


@pytest.fixture(scope='module')
def system(ros_domain: int) -> Iterator[dict[str, Proc]]:
    """The seed system, with the sensor and controller in namespace /robot1 (a cluster)."""
    with reference_system({'sensor': '/robot1', 'controller': '/robot1'}) as procs:
        robot_lab.wait_for_nodes(['/robot1/sensor', '/robot1/controller', '/robot'], timeout=10)
        yield procs


def test_model_has_nodes_topics_and_edges(system: dict[str, Proc]) -> None:
    graph = graph_model()
    kinds = dict(graph.nodes(data='kind'))
    assert kinds == {
        '/robot1/sensor': 'node', '/robot1/controller': 'node', '/robot': 'node',
        '/sensor/temperature': 'topic', '/robot/status': 'topic', '/cmd_vel': 'topic',
    }
    assert set(graph.edges) == {
        ('/robot1/sensor', '/sensor/temperature'),
        ('/sensor/temperature', '/robot1/controller'),
        ('/robot1/controller', '/cmd_vel'),
        ('/robot1/controller', '/robot/status'),
        ('/cmd_vel', '/robot'),
        ('/robot/status', '/robot'),
    }
    assert graph.edges['/robot1/sensor', '/sensor/temperature']['kind'] == 'publish'
    assert graph.edges['/cmd_vel', '/robot']['kind'] == 'subscribe'
    assert graph.nodes['/robot1/sensor']['namespace'] == '/robot1'
    assert graph.nodes['/cmd_vel']['types'] == ['geometry_msgs/msg/Twist']


def test_hidden_things_only_on_request(system: dict[str, Proc]) -> None:
    everything = graph_model(include_hidden=True, hide_topics=())
    assert '/rosout' in everything and '/parameter_events' in everything
    assert any(v.startswith('/_robot_lab_') for v in everything)  # this process's session
    assert ('/robot', '/rosout') in everything.edges


def test_picture_files_and_notebook_display(system: dict[str, Proc], tmp_path: Path) -> None:
    image = robot_lab.graph_view()
    png, shown = image._repr_png_()
    assert png.startswith(b'\x89PNG')
    assert 0 < shown['width'] <= GraphImage.DISPLAY_WIDTH  # fits a notebook output area
    svg, _ = image._repr_svg_()
    assert '<svg' in svg and '/robot1/controller' in svg and '/robot1' in svg
    assert image.save(tmp_path / 'g.png').read_bytes().startswith(b'\x89PNG')
    assert '/sensor/temperature' in image.save(tmp_path / 'g.svg').read_text()
    with pytest.raises(GraphError, match='cannot save a graph picture'):
        image.save(tmp_path / 'g.gif')
    assert repr(image) == '<GraphImage: 3 nodes, 3 topics, 6 edges>'


def test_cli_writes_the_picture(system: dict[str, Proc], tmp_path: Path) -> None:
    out = tmp_path / 'graph.svg'
    result = run_cli('graph', '-o', str(out))
    assert result.returncode == 0, result.stderr
    assert result.stdout == f'{out}: <GraphImage: 3 nodes, 3 topics, 6 edges>\n'
    text = out.read_text()
    assert text.startswith('<?xml') and '/robot1/sensor' in text
