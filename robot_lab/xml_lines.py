"""XML read with each element's line: launch files, URDF and SDF all need one reader.

ElementTree drops line numbers, and every refusal the kit prints about an XML file names
the file and line of the element at fault (`robot.launch.xml:12`, `robot.urdf:30`), so the
tree is built with expat directly. Each caller raises its own error class (a LaunchError
for a launch file, a UrdfError for a URDF, a plain RobotLabError that `doctor` turns into a
finding for package.xml, ...), passed in, so this module imports nothing of the kit but
`errors`.
"""

from __future__ import annotations

import xml.parsers.expat
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, TypeVar

from robot_lab.errors import RobotLabError

if TYPE_CHECKING:
    from typing_extensions import Self

__all__ = ['XmlElement', 'parse_xml_lines']

WELL_FORMED_FIX = 'close every tag and quote every attribute'


@dataclass
class XmlElement:
    """One element: tag, attributes, source line, stripped text (SDF keeps values there),
    and the line of its end tag (doctor points a missing child there)."""

    tag: str
    attrib: dict[str, str]
    line: int
    source: str = ''
    text: str = ''
    children: list[Self] = field(default_factory=list)
    end_line: int = 0

    def find(self, tag: str) -> Self | None:
        return next((child for child in self.children if child.tag == tag), None)

    def findall(self, tag: str) -> list[Self]:
        return [child for child in self.children if child.tag == tag]

    @property
    def where(self) -> str:
        """`file:line`, the prefix of a warning about this element."""
        return f'{self.source}:{self.line}'


E = TypeVar('E', bound=XmlElement)


def parse_xml_lines(text: str | bytes, source: str, element: type[E], error: type[RobotLabError],
                    what: str = 'not well-formed XML', fix: str = WELL_FORMED_FIX) -> E:
    """The document's root `element`; malformed XML is `error` at expat's line.

    `element` is XmlElement or a subclass adding a format's own readers (SDF's numbers).
    """
    parser = xml.parsers.expat.ParserCreate()
    stack: list[E] = []
    roots: list[E] = []
    texts: list[list[str]] = []

    def start(tag: str, attrib: dict[str, str]) -> None:
        node = element(tag, dict(attrib), parser.CurrentLineNumber, source)
        (stack[-1].children if stack else roots).append(node)
        stack.append(node)
        texts.append([])

    def end(tag: str) -> None:
        node = stack.pop()
        node.text, node.end_line = ''.join(texts.pop()).strip(), parser.CurrentLineNumber

    def data(chunk: str) -> None:
        if texts:
            texts[-1].append(chunk)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = data
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as exc:
        raise error(f'{what}: {xml.parsers.expat.ErrorString(exc.code)}', file=source,
                    line=exc.lineno, fix=fix) from None
    return roots[0]
