"""The lines an OpenDRIVE lane section paints on a carriageway: each lane's road mark lies
on its outer border; a boundary between the carriageway's lanes takes the mark of the lane
nearer the reference line, its inner edge the mark of the lane inside its innermost (the
centre lane's where that is the reference line). The same rule on either side of the
reference line (the route right of it, a far carriageway left of it: `far_side`)."""

from __future__ import annotations

from collections.abc import Sequence

from world.hdmap import LineMark, LinePaint, MarkKind, PaintColour
from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.model import OdrLane, OpenDrive, RoadMark

MARK_KINDS = {"solid": MarkKind.SOLID, "broken": MarkKind.BROKEN, "none": MarkKind.NONE}
WHITE = frozenset({"standard", "white"})


def carriageway_paint(odr: OpenDrive, drive: Sequence[OdrLane], inside: OdrLane,
                      oncoming: Sequence[OdrLane] = ()) -> LinePaint:
    """The paint of a carriageway of `drive` lanes (nearest the reference line first) whose
    innermost lane's inner neighbour is `inside` (module doc): its lane 0 (the outermost)
    edge first; `oncoming` lanes adjoining it, nearest first."""
    marks = [lane_mark(odr, lane) for lane in reversed(drive)]  # outermost first
    return LinePaint(right_edge=marks[0], lane_lines=tuple(marks[1:]),
                     left_edge=lane_mark(odr, inside),
                     oncoming=tuple(lane_mark(odr, lane) for lane in oncoming))


def lane_mark(odr: OpenDrive, lane: OdrLane) -> LineMark:
    """The line painted on `lane`'s outer border; `OpenDriveError` for marks not supported
    yet (marks that change along the section, types other than solid / broken / none,
    colours other than white / yellow)."""
    if not lane.road_marks:
        return LineMark(MarkKind.NONE, 0.0)
    if len(lane.road_marks) > 1:
        raise _refuse(odr, f"lane {lane.id}: road marks that change along the lane section")
    mark: RoadMark = lane.road_marks[0]
    kind = MARK_KINDS.get(mark.type)
    if kind is None:
        raise _refuse(odr, f"lane {lane.id}: road mark type {mark.type!r}")
    if mark.color not in WHITE and mark.color != "yellow":
        raise _refuse(odr, f"lane {lane.id}: road mark colour {mark.color!r}")
    colour = PaintColour.YELLOW if mark.color == "yellow" else PaintColour.WHITE
    return LineMark(kind, mark.width, colour)


def _refuse(odr: OpenDrive, what: str) -> OpenDriveError:
    return OpenDriveError(odr.path, f"not supported yet ({what})")
