"""XML with each element's line and text: what SDF and `<gazebo>` tags need to be read.

SDF and Gazebo's URDF extensions put their values in element text, and every refusal or
warning the simulator prints names the element's file and line; `xml_lines` reads it, as it
reads launch files and URDF, and `Node` adds SDF's number readers.
"""

from __future__ import annotations

from collections.abc import Callable

from robot_lab.errors import RobotLabError
from robot_lab.xml_lines import XmlElement, parse_xml_lines

__all__ = ['Node', 'SimulationError', 'Warn', 'parse', 'vector']

Warn = Callable[[str], None]


class SimulationError(RobotLabError):
    """A world or robot the simulator cannot build (file:line, what, how to fix it)."""


class Node(XmlElement):
    """One XML element (tag, attributes, stripped text, children, line) and SDF's readers."""

    def value(self, tag: str, default: str = '') -> str:
        child = self.find(tag)
        return child.text if child is not None and child.text else default

    def number(self, tag: str, default: float) -> float:
        child = self.find(tag)
        if child is None or not child.text:
            return default
        try:
            return float(child.text)
        except ValueError:
            raise SimulationError(f'<{tag}> is {child.text!r}, not a number',
                                  file=self.source, line=child.line,
                                  fix=f'write a number, e.g. <{tag}>{default:g}</{tag}>') from None


def parse(text: str | bytes, source: str) -> Node:
    """The document's root element; malformed XML is a SimulationError at expat's line."""
    return parse_xml_lines(text, source, Node, SimulationError)


def vector(node: Node | None, count: int, default: float = 0.0) -> list[float]:
    """`count` numbers from an element's text (an SDF `<pose>`, `<size>`), padded."""
    if node is None or not node.text:
        return [default] * count
    try:
        values = [float(v) for v in node.text.split()]
    except ValueError:
        raise SimulationError(f'<{node.tag}> is {node.text!r}, not {count} numbers',
                              file=node.source, line=node.line,
                              fix=f'write {count} numbers separated by spaces') from None
    if len(values) > count:
        raise SimulationError(f'<{node.tag}> has {len(values)} numbers, not {count}',
                              file=node.source, line=node.line,
                              fix=f'write {count} numbers separated by spaces')
    return values + [default] * (count - len(values))
