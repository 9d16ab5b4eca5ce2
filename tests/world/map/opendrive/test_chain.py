"""Roads linked end to end as one route: the merged road lies on the file's roads, exactly;
each road keeps its own limit; what is not one line of roads is refused in one line."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from world.map.opendrive import (
    OpenDriveError,
    chain_roads,
    lane_centre_t,
    load_opendrive,
)
from world.map.opendrive.route import build_route
from world.map.road import build_road_map

DATA = Path(__file__).with_name("data")
LINKED = DATA / "linked.xodr"
REF_T = -5.25  # [m] route lane 0 (lane -2) centre: 1.5 lanes of 3.5 m right of the line
TURNS = {"1": 0.0, "2": 0.01 * 60.0 / 2.0, "3": 0.01 * 80.0}  # [rad] each road's turn


def test_the_chain_runs_along_the_links_whatever_the_files_order() -> None:
    odr = load_opendrive(LINKED)
    assert [road.id for road in odr.roads] == ["3", "1", "2"]
    chain = chain_roads(odr)
    assert [span.road_id for span in chain.spans] == ["1", "2", "3"]
    assert chain.starts == {"1": 0.0, "2": 100.0, "3": 160.0}
    assert chain.road.id == "1+2+3" and chain.road.length == pytest.approx(240.0)
    assert chain.locate(170.0) == ("3", pytest.approx(10.0))
    assert chain.locate(100.0) == ("2", 0.0)  # the later road at a joint
    # the lane links were read (and keep every lane's id)
    lane = odr.road("1").lane_sections[0].lane(-1)
    assert (lane.predecessors, lane.successors) == ((-1,), (-1,))


def test_a_file_of_one_road_is_that_road() -> None:
    odr = load_opendrive(DATA / "curvy.xodr")
    chain = chain_roads(odr)
    assert chain.road is odr.roads[0]
    assert chain.starts == {"1": 0.0}


def test_the_route_is_as_long_as_lane_0s_centre_on_every_road() -> None:
    """Lane 0's centre, 5.25 m right of the reference line, is L - t * turn long on each
    road (the arc spline keeps each record's turn exactly)."""
    route = build_route(load_opendrive(LINKED))
    road_map = build_road_map(route.spec)
    assert route.layout.lane_ids == (-2, -1) and route.layout.ref_t == pytest.approx(REF_T)
    lengths = {"1": 100.0, "2": 60.0, "3": 80.0}
    want = sum(lengths[i] - REF_T * TURNS[i] for i in lengths)
    assert want == pytest.approx(245.775)
    assert road_map.length == pytest.approx(want, abs=1e-6)


@pytest.mark.parametrize("road_id", ["1", "2", "3"])
def test_the_maps_lanes_lie_on_each_files_road_exactly(road_id: str) -> None:
    """Every route lane's centre within 1 mm of the file's lane centre along each road, as
    the file road's own geometry puts it (not the merged road's)."""
    odr = load_opendrive(LINKED)
    route = build_route(odr)
    road_map = build_road_map(route.spec)
    road = odr.road(road_id)
    for index, lane_id in enumerate(route.layout.lane_ids):
        for s in np.linspace(0.0, road.length, 101):
            x, y, h = (float(v[0]) for v in road.plan_view.pose(np.array([s])))
            t = lane_centre_t(road, lane_id, float(s))
            point = (x - t * math.sin(h), y + t * math.cos(h))
            lane, _, r = road_map.lane_at(point)
            assert lane == index and abs(r) < 1e-3, (road_id, lane_id, s, lane, r)
            merged = route.point(route.chain.starts[road_id] + float(s), t)
            assert math.dist(merged[:2], point) < 1e-9


def test_each_road_keeps_its_own_limit() -> None:
    """Road 2 posts 80 km/h; roads 1 and 3 post none: the route's default (the 'unknown'
    type's 100 km/h), not road 2's limit carried on."""
    route = build_route(load_opendrive(LINKED))
    road_map = build_road_map(route.spec)
    for road_id, s, kph in [("1", 50.0, 100.0), ("2", 1.0, 80.0), ("2", 59.0, 80.0),
                            ("3", 1.0, 100.0), ("3", 79.0, 100.0)]:
        x, y, _ = route.point(route.chain.starts[road_id] + s, REF_T)
        s_map, _ = road_map.local_coordinates((x, y))
        assert float(road_map.speed_limit_at(s_map)) == pytest.approx(kph / 3.6), road_id


CENTRE = '<center><lane id="0" type="none"/></center>'
LANE = ('<lane id="-1" type="driving">{link}<width sOffset="0" a="3.5" b="0" c="0" d="0"/>'
        '</lane>')


def road(i: int, links: str = "", y: float = 0.0, junction: str = "-1",
         lane_link: str = "") -> str:
    """Road `i`: 100 m straight along +x from x = 100 i, one driving lane right."""
    return (f'<road length="100" id="{i}" junction="{junction}"><link>{links}</link>'
            f'<planView><geometry s="0" x="{100 * i}" y="{y}" hdg="0" length="100"><line/>'
            f'</geometry></planView><lanes><laneSection s="0">{CENTRE}<right>'
            f'{LANE.format(link=lane_link)}</right></laneSection></lanes></road>')


def to(i: int, contact: str = "start", kind: str = "road") -> str:
    return f'<successor elementType="{kind}" elementId="{i}" contactPoint="{contact}"/>'


def back(i: int, contact: str = "end") -> str:
    return f'<predecessor elementType="road" elementId="{i}" contactPoint="{contact}"/>'


@pytest.mark.parametrize(("roads", "problem"), [
    ([road(1, to(2)), road(2, y=0.5)],
     "road 2 does not start where road 1 ends: 0.5 m apart, headings 0 rad apart"),
    ([road(1, to(2, "end")), road(2)],
     "not supported yet (road 2 joined at its end: a reversed road)"),
    ([road(1), road(2, back(1, "start"))],
     "not supported yet (road 1 joined at its start: a reversed road)"),
    ([road(1, to(9, kind="junction")), road(2)],
     "not supported yet (junctions: road 1's successor is junction 9)"),
    ([road(1, to(2)), road(2, junction="4")],
     "not supported yet (junctions: road 2 is in junction 4)"),
    ([road(1), road(2)],
     "not supported yet (roads not linked end to end into one route: road networks)"),
    ([road(1, to(2)), road(2), road(3)],
     "not supported yet (roads not linked end to end into one route: road networks)"),
    ([road(1, to(2)), road(2, to(1))], "not supported yet (roads linked in a loop)"),
    ([road(1, to(2)), road(2, back(3)), road(3, to(2))],
     "the road links contradict each other: road 2 is linked to roads 1 and 3"),
    ([road(1, to(2), lane_link='<link><successor id="-2"/></link>'), road(2)],
     "not supported yet (lane links that renumber lanes: lane -1 linked to lane -2 "
     "between roads 1 and 2)"),
    ([road(1, to(2)), road(2, lane_link='<link><predecessor id="1"/></link>')],
     "not supported yet (lane links that renumber lanes: lane -1 linked to lane 1"),
])
def test_what_is_not_one_line_of_roads_is_refused_in_one_line(
        tmp_path: Path, roads: list[str], problem: str) -> None:
    path = tmp_path / "net.xodr"
    path.write_text('<?xml version="1.0"?><OpenDRIVE><header revMajor="1" revMinor="6"/>'
                    + "".join(roads) + "</OpenDRIVE>")
    with pytest.raises(OpenDriveError) as err:
        build_route(load_opendrive(path))
    assert problem in str(err.value)
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)


def test_links_out_of_the_file_and_agreeing_links_both_ways_are_followed(
        tmp_path: Path) -> None:
    roads = [road(2, back(1) + to(7)), road(1, back(5, "start") + to(2)),
             road(3, back(2, "end"))]
    path = tmp_path / "line.xodr"
    path.write_text('<?xml version="1.0"?><OpenDRIVE><header revMajor="1" revMinor="6"/>'
                    + "".join(roads) + "</OpenDRIVE>")
    # road 2's successor 7 is not in the file: it leads out, and road 3 follows road 2 by
    # its own predecessor link alone
    chain = chain_roads(load_opendrive(path))
    assert chain.starts == {"1": 0.0, "2": 100.0, "3": 200.0}
