"""Bounding a YAML text by its parser's events, before anything is composed.

PyYAML composes a document recursively (libyaml's binding in C, without a limit: a text
nested 50,000 deep crashes the process) and expands nothing until construction, when a few
nested anchors or merge keys may ask for billions of values. The parser's event stream is
produced one event at a time by a loop over explicit stacks, so `check_events` walks it
first and refuses a text

- nested deeper than `MAX_DEPTH` collections (a mapping or list inside another counts one
  level; an alias counts the levels of its anchor's node where it is used), or
- holding more than `MAX_VALUES` values (scalars, lists and mappings, keys included), every
  alias counting its anchor's node in full: an anchor's expanded size is known when its node
  ends, and a merge key's alias (``<<: *a``) adds it like any other.

The walk stops at the first event past a bound, so its work is bounded by the bounds, not by
the text (libyaml's scanner costs time in the flow depth per token: a walk over a whole text
nested 50,000 deep would take seconds). An alias to an anchor whose node is still open (a
recursive structure) is refused too. Problems are `YamlBoundError`s at the line of the event.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import yaml

from avsim.scenario.bounds import MAX_DEPTH, MAX_VALUES

if TYPE_CHECKING:
    _Parser = yaml.SafeLoader
else:  # libyaml's parser where PyYAML has it: iterative like the pure Python one, 30x faster
    _Parser = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader


class YamlBoundError(yaml.YAMLError):
    """A YAML text over one of the loader's bounds, at 1-based `line`."""

    def __init__(self, line: int, problem: str) -> None:
        super().__init__(f"line {line}: {problem}")
        self.line = line
        self.problem = problem


@dataclass(slots=True)
class _Open:
    """A collection whose end event has not come yet."""

    anchor: str | None  # its anchor, if it has one
    size: int = 1  # values in it so far, itself included, aliases expanded
    height: int = 1  # collection levels in it so far, itself included, aliases expanded


@dataclass(slots=True)
class _Walk:
    """The state of one walk over a text's events."""

    values: int = 0  # values so far in the whole text, aliases expanded
    anchors: dict[str, tuple[int, int] | None] = field(default_factory=dict)  # -> (size,
    # height) of its node once it has ended; None while it is open
    open: list[_Open] = field(default_factory=list)  # the enclosing collections, outermost first

    def count(self, size: int, height: int, line: int) -> None:
        """Count a node of `size` values and `height` collection levels at the current depth
        into the text's total, refusing it past a bound."""
        self.values += size
        if self.values > MAX_VALUES:
            raise YamlBoundError(line, f"more than {MAX_VALUES} values (anchors expanded)")
        if len(self.open) + height > MAX_DEPTH:
            raise YamlBoundError(line, f"nested deeper than {MAX_DEPTH} levels"
                                       " (anchors expanded)")

    def into_parent(self, size: int, height: int) -> None:
        """Add a finished node of `size` values and `height` levels to its collection."""
        if self.open:
            parent = self.open[-1]
            parent.size += size
            parent.height = max(parent.height, height + 1)

    def alias(self, event: yaml.AliasEvent, line: int) -> None:
        """Count an alias as its anchor's node in full."""
        anchor = str(event.anchor)
        if anchor in self.anchors and self.anchors[anchor] is None:
            raise YamlBoundError(line, f"alias *{anchor} inside its own anchor's node")
        size, height = self.anchors.get(anchor) or (1, 0)  # undefined: the composer says so
        self.count(size, height, line)
        self.into_parent(size, height)

    def start(self, event: yaml.CollectionStartEvent, line: int) -> None:
        """Open a collection: it counts one value and one level now, its content as it comes."""
        self.count(1, 1, line)
        self.open.append(_Open(event.anchor))
        if event.anchor is not None:
            self.anchors[event.anchor] = None

    def end(self) -> None:
        """Close the innermost collection: its anchor's expanded size and height are known."""
        node = self.open.pop()
        if node.anchor is not None:
            self.anchors[node.anchor] = (node.size, node.height)
        self.into_parent(node.size, node.height)

    def scalar(self, event: yaml.ScalarEvent, line: int) -> None:
        """Count a scalar: one value, no level."""
        self.count(1, 0, line)
        self.into_parent(1, 0)
        if event.anchor is not None:
            self.anchors[event.anchor] = (1, 0)


def check_events(text: str) -> None:
    """Walk the events of `text` (module doc); a `YamlBoundError` past a bound, PyYAML's
    `MarkedYAMLError` for a syntax error met on the way."""
    walk = _Walk()
    for event in yaml.parse(text, Loader=_Parser):
        line = event.start_mark.line + 1 if event.start_mark is not None else 0
        if isinstance(event, yaml.ScalarEvent):
            walk.scalar(event, line)
        elif isinstance(event, yaml.AliasEvent):
            walk.alias(event, line)
        elif isinstance(event, yaml.CollectionStartEvent):
            walk.start(event, line)
        elif isinstance(event, yaml.CollectionEndEvent):
            walk.end()
        elif isinstance(event, yaml.DocumentStartEvent):
            walk.anchors.clear()  # anchors are a document's own
