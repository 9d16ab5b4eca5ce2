"""The OpenDRIVE map kind: an ASAM OpenDRIVE (.xodr, 1.4-1.8) reader with exact
reference-line geometry (`load_opendrive`, `PlanView`, `arc_spline`, lane borders) and
roads linked end to end merged into one (`chain_roads`)."""

from __future__ import annotations

from world.map.opendrive.arcspline import ArcPiece, arc_spline, piece_deviation
from world.map.opendrive.chain import Chain, Span, chain_roads
from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.lanes import (
    lane_borders,
    lane_centre_t,
    lane_offset,
    lane_section_index,
    lane_width,
)
from world.map.opendrive.model import (
    Arc,
    Geometry,
    LaneSection,
    Line,
    Link,
    OdrLane,
    OpenDrive,
    ParamPoly3,
    Poly3,
    Poly3Shape,
    Road,
    RoadMark,
    Shape,
    SpeedRecord,
    Spiral,
    poly3_at,
)
from world.map.opendrive.parse import load_opendrive

__all__ = [
    "Arc",
    "ArcPiece",
    "Chain",
    "Geometry",
    "LaneSection",
    "Line",
    "Link",
    "OdrLane",
    "OpenDrive",
    "OpenDriveError",
    "ParamPoly3",
    "PlanView",
    "Poly3",
    "Poly3Shape",
    "Road",
    "RoadMark",
    "Shape",
    "Span",
    "SpeedRecord",
    "Spiral",
    "arc_spline",
    "chain_roads",
    "lane_borders",
    "lane_centre_t",
    "lane_offset",
    "lane_section_index",
    "lane_width",
    "load_opendrive",
    "piece_deviation",
    "poly3_at",
]
