"""A safe XML element tree with the line of each start tag, built with the stdlib expat
parser, for the map and scenario file readers (OpenDRIVE, OpenSCENARIO) to wrap with their
own nodes and messages.

Safe: a DOCTYPE or an entity declaration is refused (nothing is expanded), no external
entity is fetched, and the number of elements is bounded. Problems are raised as
`XmlRefusedError` (what was refused, where) or `XmlMalformedError` (expat's message, where).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from typing import Any, Protocol, TypeVar
from xml.parsers import expat


class Refusal(enum.Enum):
    DOCTYPE = "doctype"
    ENTITY = "entity"
    TOO_MANY = "too many elements"


class XmlRefusedError(Exception):
    """The document uses something refused (`what`), at `line` (1-based)."""

    def __init__(self, what: Refusal, line: int) -> None:
        super().__init__(what, line)
        self.what = what
        self.line = line


class XmlMalformedError(Exception):
    """The document is not well-formed: expat's `problem` at `line` (1-based)."""

    def __init__(self, problem: str, line: int) -> None:
        super().__init__(problem, line)
        self.problem = problem
        self.line = line


class Element(Protocol):
    """What a reader's node must have: its child elements, in file order."""

    children: list[Any]


N = TypeVar("N", bound=Element)


def parse_tree(data: bytes, make: Callable[[str, dict[str, str], int, N | None], N],
               max_elements: int) -> N | None:
    """The root of the document `data`, its nodes made by `make(tag, attributes, line,
    parent)` and appended to their parent's `children`; None for a document without an
    element."""
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[N] = []
    roots: list[N] = []
    count = 0

    def start(tag: str, attrib: dict[str, str]) -> None:
        nonlocal count
        count += 1
        if count > max_elements:
            raise XmlRefusedError(Refusal.TOO_MANY, parser.CurrentLineNumber)
        parent = stack[-1] if stack else None
        node = make(tag, attrib, parser.CurrentLineNumber, parent)
        (parent.children if parent is not None else roots).append(node)
        stack.append(node)

    def end(_tag: str) -> None:
        stack.pop()

    def doctype(*_args: object) -> None:
        raise XmlRefusedError(Refusal.DOCTYPE, parser.CurrentLineNumber)

    def entity(*_args: object) -> None:
        raise XmlRefusedError(Refusal.ENTITY, parser.CurrentLineNumber)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler = entity
    parser.ExternalEntityRefHandler = lambda *_a: 0  # never fetch anything
    try:
        parser.Parse(data, True)
    except expat.ExpatError as e:
        problem = expat.ErrorString(e.code) if e.code is not None else str(e)
        raise XmlMalformedError(problem, e.lineno) from None
    return roots[0] if roots else None
