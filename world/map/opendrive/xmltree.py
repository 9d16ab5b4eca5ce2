"""A minimal, safe XML element tree with the line of each start tag, for error messages.

Built by `world.core.safe_xml` (expat): no DTD (a DOCTYPE is refused, so no entity
expansion), a bounded number of elements. Each `Node` knows its file, line and path
(`/OpenDRIVE/road[id=0]/planView/geometry[3]/spiral`: an element with an `id` attribute is
named by it, one of several same-tag siblings by its 1-based position as in XPath).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from world.core.safe_xml import Refusal, XmlMalformedError, XmlRefusedError, parse_tree
from world.map.opendrive.errors import OpenDriveError

MAX_ELEMENTS = 1_000_000  # elements in one file (refused past it in 2.9 s: bench/bench_load.py)
MAX_MAGNITUDE = 1e9  # no number in a file is larger (coordinates [m], lengths, coefficients)
MAX_NUMBER_CHARS = 64  # characters of one number attribute (a double needs under 25)
SHOWN_CHARS = 40  # characters of a bad value quoted in an error message
IGNORED = frozenset({"userData"})  # children skipped wherever they appear
NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
# how an unsupported element is named in "not supported yet (...)", where not by its tag
UNSUPPORTED_AS = {"junction": "junctions", "border": "lane border"}


def shown(raw: str) -> str:
    """`raw` quoted for an error message, cut to `SHOWN_CHARS` characters."""
    if len(raw) <= SHOWN_CHARS:
        return repr(raw)
    return f"{raw[:SHOWN_CHARS]!r}... ({len(raw)} characters)"


@dataclass(eq=False, slots=True)
class Node:
    """One element: tag, attributes, children (in file order), where it is."""

    tag: str
    attrib: dict[str, str]
    file: str
    line: int  # 1-based line of its start tag
    parent: Node | None = None
    children: list[Node] = field(default_factory=list)

    @property
    def path(self) -> str:
        """Its element path from the root (module doc)."""
        here = self.tag
        if "id" in self.attrib:
            here += f"[id={self.attrib['id']}]"
        elif self.parent is not None:
            same = [c for c in self.parent.children if c.tag == self.tag]
            if len(same) > 1:
                here += f"[{next(i for i, c in enumerate(same) if c is self) + 1}]"
        return (self.parent.path if self.parent is not None else "") + "/" + here

    def error(self, problem: str) -> OpenDriveError:
        """The error `problem` at this element."""
        return OpenDriveError(self.file, problem, self.line, self.path)

    def unsupported(self, what: str | None = None) -> OpenDriveError:
        """'not supported yet (what)' at this element (`what` defaults to its tag)."""
        name = what or UNSUPPORTED_AS.get(self.tag, self.tag)
        return self.error(f"not supported yet ({name})")

    def get(self, name: str, default: str | None = None) -> str:
        """The attribute `name`, else `default`; an error if missing and no default."""
        value = self.attrib.get(name, default)
        if value is None:
            raise self.error(f"missing attribute {name}")
        return value

    def num(self, name: str, default: float | None = None) -> float:
        """The finite number attribute `name` (else `default`)."""
        raw = self.attrib.get(name)
        if raw is None:
            if default is None:
                raise self.error(f"missing attribute {name}")
            return default
        if len(raw) > MAX_NUMBER_CHARS:
            raise self.error(f"{name} is {len(raw)} characters long, over the "
                             f"{MAX_NUMBER_CHARS} of a number ({shown(raw)})")
        if not NUMBER.fullmatch(raw.strip()):
            raise self.error(f"{name} is not a number ({shown(raw)})")
        value = float(raw)
        if not math.isfinite(value):
            raise self.error(f"{name} is not a finite number ({shown(raw)})")
        if abs(value) > MAX_MAGNITUDE:
            raise self.error(f"{name} is beyond the limit of {MAX_MAGNITUDE:g} ({shown(raw)})")
        return value

    def integer(self, name: str, default: int | None = None) -> int:
        """The integer attribute `name` (else `default`)."""
        raw = self.attrib.get(name)
        if raw is None:
            if default is None:
                raise self.error(f"missing attribute {name}")
            return default
        if not re.fullmatch(r"[+-]?\d{1,18}", raw.strip()):
            raise self.error(f"{name} is not an integer ({shown(raw)})")
        return int(raw)

    def only(self, *allowed: str) -> dict[str, list[Node]]:
        """Its children by tag; an unsupported-error for a child not `allowed` (userData is
        skipped)."""
        groups: dict[str, list[Node]] = {tag: [] for tag in allowed}
        for child in self.children:
            if child.tag in IGNORED:
                continue
            if child.tag not in groups:
                raise child.unsupported()
            groups[child.tag].append(child)
        return groups

    def at_most_one(self, nodes: list[Node], tag: str) -> Node | None:
        """The single node of `nodes` (children `tag`), None if none; an error if several."""
        if len(nodes) > 1:
            raise nodes[1].error(f"more than one <{tag}>")
        return nodes[0] if nodes else None

    def exactly_one(self, nodes: list[Node], tag: str) -> Node:
        """The single node of `nodes` (children `tag`); an error if none or several."""
        node = self.at_most_one(nodes, tag)
        if node is None:
            raise self.error(f"missing <{tag}>")
        return node


def parse_xml(file: str, data: bytes) -> Node:
    """The root element of the XML document `data` read from `file` (`world.core.safe_xml`)."""

    def make(tag: str, attrib: dict[str, str], line: int, parent: Node | None) -> Node:
        return Node(tag, attrib, file, line, parent)

    try:
        root = parse_tree(data, make, MAX_ELEMENTS)
    except XmlMalformedError as e:
        raise OpenDriveError(file, f"malformed XML at line {e.line}: {e.problem}") from None
    except XmlRefusedError as e:
        problem = _REFUSED[e.what].format(line=e.line, max_elements=MAX_ELEMENTS)
        raise OpenDriveError(file, problem) from None
    if root is None:
        raise OpenDriveError(file, "no root element")
    return root


_REFUSED = {Refusal.TOO_MANY: "more than {max_elements} elements (line {line})",
            Refusal.DOCTYPE: "DOCTYPE at line {line} refused (no DTDs)",
            Refusal.ENTITY: "entity declaration at line {line} refused"}
