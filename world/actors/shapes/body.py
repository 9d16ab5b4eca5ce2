"""A body: its named convex parts, the dimensions its bounding box has, and their source."""

from __future__ import annotations

from dataclasses import dataclass

from world.actors.shapes.parts import BodyPart


@dataclass(frozen=True, slots=True)
class Body:
    """One body's shape in the body frame (see the package's docstring)."""

    name: str  # snake_case: the asset's file name
    parts: tuple[BodyPart, ...]
    length: float  # [m] along x: its bounding box's
    width: float  # [m] along y
    height: float  # [m] along z, from the ground
    source: str  # where the dimensions come from
