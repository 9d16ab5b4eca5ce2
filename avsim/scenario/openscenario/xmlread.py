"""Safe XML reading with line numbers: a small element tree (`Node`) built with expat.

DOCTYPE declarations and entities are refused (nothing is expanded), the file size and the
number of elements are bounded, and a UTF-8 byte-order mark is accepted. Every node knows
its file, its line and its path (`/OpenSCENARIO/Storyboard/Story[CutInStory]/...`, with the
`name` attribute in brackets where present) so that any problem is reported as one line
`<file>: line N: <path>: <problem>`.
"""

from __future__ import annotations

from pathlib import Path

from avsim.scenario.errors import ScenarioError
from world.core.safe_read import UnreadableFileError, read_bounded
from world.core.safe_xml import Refusal, XmlMalformedError, XmlRefusedError, parse_tree

MAX_FILE_BYTES = 20 * 1024 * 1024  # the largest file read [bytes]
MAX_ELEMENTS = 200_000  # the most elements a file may hold
MAX_PATH_NAME = 40  # [characters] of a `name` shown in an element's path


class Node:
    """An XML element: tag, attributes (as written), child elements, and where it is."""

    __slots__ = ("attrs", "children", "file", "line", "parent", "tag")

    def __init__(
        self, tag: str, attrs: dict[str, str], file: str, line: int, parent: Node | None
    ) -> None:
        self.tag = tag
        self.attrs = attrs
        self.file = file
        self.line = line
        self.parent = parent
        self.children: list[Node] = []

    @property
    def path(self) -> str:
        """`/OpenSCENARIO/Storyboard/Story[CutInStory]`: tags from the root, with names."""
        parts: list[str] = []
        node: Node | None = self
        while node is not None:
            name = node.attrs.get("name")
            if name is not None and len(name) > MAX_PATH_NAME:  # a message stays one short line
                name = name[: MAX_PATH_NAME - 3] + "..."
            parts.append(f"{node.tag}[{name}]" if name is not None else node.tag)
            node = node.parent
        return "/" + "/".join(reversed(parts))

    @property
    def key(self) -> str:
        """The key of a problem here: `line N: <path>`."""
        return f"line {self.line}: {self.path}"

    def error(self, problem: str) -> ScenarioError:
        """A `ScenarioError` at this element (to raise)."""
        return ScenarioError(self.file, self.key, problem)

    def child(self, tag: str) -> Node | None:
        """The first child element with this tag, or None."""
        for c in self.children:
            if c.tag == tag:
                return c
        return None

    def need(self, tag: str) -> Node:
        """The first child element with this tag; an error when there is none."""
        found = self.child(tag)
        if found is None:
            raise self.error(f"missing element {tag}")
        return found

    def all(self, tag: str) -> list[Node]:
        """Every child element with this tag, in order."""
        return [c for c in self.children if c.tag == tag]

    def only_child(self) -> Node:
        """The single child element of a choice element (`<Position><LanePosition/>`)."""
        if len(self.children) != 1:
            raise self.error(f"expected exactly one child element, found {len(self.children)}")
        return self.children[0]


def read_xml(
    path: Path, *, max_bytes: int = MAX_FILE_BYTES, max_elements: int = MAX_ELEMENTS
) -> Node:
    """The root element of the XML file at `path` (`read_xml_sized`)."""
    return read_xml_sized(path, max_bytes, max_elements)[0]


def read_xml_sized(
    path: Path, max_bytes: int = MAX_FILE_BYTES, max_elements: int = MAX_ELEMENTS
) -> tuple[Node, int]:
    """The root element of the XML file at `path` and its size [bytes]; `ScenarioError` when
    it is not a regular file (a FIFO, a device, a directory, a symlink loop: `read_bounded`),
    is too large, is not well-formed, or declares a DOCTYPE or entities."""
    file = str(path)
    try:
        data = read_bounded(path, max_bytes)
    except UnreadableFileError as exc:
        raise ScenarioError(file, "(file)", exc.problem) from None
    return parse_xml_bytes(data, file, max_elements=max_elements), len(data)


def parse_xml_bytes(data: bytes, file: str, *, max_elements: int = MAX_ELEMENTS) -> Node:
    """The root element of an XML document given as bytes (see `read_xml`;
    `world.core.safe_xml` parses)."""

    def make(tag: str, attrs: dict[str, str], line: int, parent: Node | None) -> Node:
        return Node(tag, attrs, file, line, parent)

    try:
        root = parse_tree(data, make, max_elements)
    except XmlRefusedError as exc:
        problem = {Refusal.TOO_MANY: f"too many elements (more than {max_elements})",
                   Refusal.DOCTYPE: "DOCTYPE declarations are not allowed",
                   Refusal.ENTITY: "entity declarations are not allowed"}[exc.what]
        raise ScenarioError(file, f"line {exc.line}", problem) from None
    except XmlMalformedError as exc:
        raise ScenarioError(file, f"line {exc.line}", f"malformed XML: {exc.problem}") from None
    if root is None:  # pragma: no cover - expat reports "no element found" first
        raise ScenarioError(file, "(file)", "no root element")
    return root
