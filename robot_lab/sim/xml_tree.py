"""XML with each element's line and text: what SDF and `<gazebo>` tags need to be read.

`robot_lab.urdf.model.Element` keeps no text (URDF puts everything in attributes); SDF and
Gazebo's URDF extensions put their values in element text, and every refusal or warning the
simulator prints names the element's file and line.
"""

from __future__ import annotations

import xml.parsers.expat
from collections.abc import Callable
from dataclasses import dataclass, field

from robot_lab.errors import RobotLabError

__all__ = ['Node', 'SimulationError', 'Warn', 'parse', 'vector']

Warn = Callable[[str], None]


class SimulationError(RobotLabError):
    """A world or robot the simulator cannot build (file:line, what, how to fix it)."""


@dataclass
class Node:
    """One XML element: its tag, attributes, stripped text, children and source line."""

    tag: str
    attrib: dict[str, str]
    line: int
    source: str
    text: str = ''
    children: list[Node] = field(default_factory=list)

    def find(self, tag: str) -> Node | None:
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag: str) -> list[Node]:
        return [c for c in self.children if c.tag == tag]

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

    @property
    def where(self) -> str:
        return f'{self.source}:{self.line}'


def parse(text: str | bytes, source: str) -> Node:
    """The document's root element; malformed XML is a SimulationError at expat's line."""
    parser = xml.parsers.expat.ParserCreate()
    stack: list[Node] = []
    roots: list[Node] = []
    texts: list[list[str]] = []

    def start(tag: str, attrib: dict[str, str]) -> None:
        node = Node(tag, dict(attrib), parser.CurrentLineNumber, source)
        (stack[-1].children if stack else roots).append(node)
        stack.append(node)
        texts.append([])

    def end(tag: str) -> None:
        stack.pop().text = ''.join(texts.pop()).strip()

    def data(chunk: str) -> None:
        if texts:
            texts[-1].append(chunk)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = data
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as exc:
        raise SimulationError(f'not well-formed XML: {xml.parsers.expat.ErrorString(exc.code)}',
                              file=source, line=exc.lineno,
                              fix='close every tag and quote every attribute') from None
    return roots[0]


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
