"""An OpenDRIVE road as the simulator's route: the HD map built from the file matches the
file's exact lanes, its paint is the file's road marks, and what does not fit is refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from world.hdmap import LineMark, MarkKind, PaintColour, RoadMap
from world.map.opendrive import OpenDriveError, lane_centre_t, load_opendrive
from world.map.opendrive.route import OdrRoute, build_route
from world.map.road import build_road_map
from world.scene.road_mesh import build_road_surface, markings

DATA = Path(__file__).with_name("data")
TOLERANCE = 1e-3  # [m] the arc spline's (`world.map.opendrive.route.TOLERANCE`)


def heading_bound(piece_length: float) -> float:
    """[rad] how far an arc of a spline within TOLERANCE of a clothoid turns from it: exact
    at the joints, the clothoid's heading off by c L^2 / 8 at mid-piece while its position
    is off by c L^3 / 12 = TOLERANCE at most, so 1.5 TOLERANCE / L (1e-9 for rounding)."""
    return 1.5 * TOLERANCE / piece_length + 1e-9
ALKS = (Path(__file__).parents[3] / "data/alks/logical_scenarios/concrete_scenarios"
        / "road_networks")


def route_and_map(path: Path) -> tuple[OdrRoute, RoadMap]:
    route = build_route(load_opendrive(path))
    return route, build_road_map(route.spec)


@pytest.mark.parametrize("path", [*sorted(ALKS.glob("*.xodr")), DATA / "curvy.xodr"],
                         ids=lambda p: p.stem)
def test_the_maps_lanes_lie_on_the_files_exact_lanes(path: Path) -> None:
    """Every route lane's centre, at stations all along the road, within 1 mm of the
    file's lane centre (the arc spline's tolerance), and its heading with it."""
    route, road_map = route_and_map(path)
    road = route.road
    for index, lane_id in enumerate(route.layout.lane_ids):
        for s in np.linspace(0.5, road.length - 0.5, 400):
            x, y, h = route.point(float(s), lane_centre_t(road, lane_id, float(s)))
            lane, _, r = road_map.lane_at((x, y))
            assert lane == index and abs(r) < 1e-3, (lane_id, s, lane, r)
            s_map, _ = road_map.local_coordinates((x, y))
            heading = float(road_map.heading_at(s_map))
            piece = road_map.pieces[int(road_map.line.segment_index(s_map))]
            assert abs(math.remainder(heading - h, 2 * math.pi)) < heading_bound(piece.length)


def test_the_alks_road_is_three_lanes_of_3_5_m_with_a_hard_shoulder() -> None:
    route, road_map = route_and_map(ALKS / "alks_road_straight.xodr")
    assert route.layout.lane_ids == (-5, -4, -3)  # route lane 0 is the outermost
    assert route.layout.oncoming_ids == ()  # the other carriageway beyond the median
    section = road_map.sections[0]
    assert (section.lanes, section.lane_width, section.shoulder) == (3, 3.5, 3.0)
    assert road_map.length == pytest.approx(10000.0)
    assert route.layout.ref_t == pytest.approx(-(2.0 + 0.75 + 2.5 * 3.5))
    # the motorway without a posted limit: its advisory 130 km/h
    assert float(road_map.speed_limit_at(100.0)) == pytest.approx(130.0 / 3.6)


@pytest.mark.parametrize("name", ["alks_road_different_curvatures.xodr", "curvy.xodr"])
def test_a_limit_is_posted_once_not_at_every_piece_of_the_spline(name: str) -> None:
    """One speed record: one posting (one sign), however many pieces the curves need."""
    path = ALKS / name if name.startswith("alks") else DATA / name
    route, road_map = route_and_map(path)
    records = {r.max_speed for r in route.road.speeds}
    assert len(road_map.pieces) > 10
    assert len(road_map.speed_limits) == 1 and len(records) <= 1


def test_the_paint_is_the_files_road_marks() -> None:
    """ALKS: 0.30 m solid edges, 0.15 m broken lane lines; painted where the map's lane
    boundaries are."""
    _, road_map = route_and_map(ALKS / "alks_road_straight.xodr")
    section = road_map.sections[0]
    assert section.paint is not None
    lines = markings(section)
    assert [(m.dashed, m.width) for m in lines] == [
        (False, 0.3), (True, 0.15), (True, 0.15), (False, 0.3)]
    # centred on the boundaries past 3 m of shoulder, the left edge line kept 0.1 m off the
    # paved edge (the median's border lanes are not paved here)
    assert [m.centre for m in lines] == pytest.approx([3.0, 6.5, 10.0, 13.5 - 0.1 - 0.15])
    assert build_road_surface(road_map)  # the meshes build with that texture


def test_a_two_way_road_paints_its_centre_line_and_oncoming_lanes() -> None:
    _, road_map = route_and_map(DATA / "curvy.xodr")
    section = road_map.sections[0]
    assert (section.lanes, section.oncoming_lanes) == (2, 2)
    assert section.paint is not None
    assert section.paint.left_edge == LineMark(MarkKind.SOLID, 0.12, PaintColour.YELLOW)
    kinds = [(m.dashed, m.rgb[2] < 100) for m in markings(section)]  # yellow: little blue
    assert kinds == [(False, False), (True, False), (False, True), (True, False),
                     (False, False)]
    assert float(road_map.speed_limit_at(50.0)) == pytest.approx(100.0 / 3.6)


def test_spirals_become_exact_offset_arcs_of_the_spline() -> None:
    """The route's pieces are offsets of the reference line's arc spline: each starts on
    the file's lane 0 centre, with its heading."""
    route, _ = route_and_map(DATA / "curvy.xodr")
    assert len(route.spec.segments) > 9  # spirals, poly3 and paramPoly3 split into arcs
    for seg in route.spec.segments[:20]:
        assert seg.start is not None
        x0, y0, h0 = seg.start
        s, t = route.road.plan_view.project(np.array([[x0, y0]]))
        assert float(t[0]) == pytest.approx(route.layout.ref_t, abs=1e-6)
        _, _, heading = route.road.plan_view.pose(s)
        assert math.remainder(h0 - float(heading[0]), 2 * math.pi) == pytest.approx(0.0,
                                                                                 abs=1e-9)


def write(tmp_path: Path, lanes: str, rule: str = "RHT", roads: int = 1) -> Path:
    road = f'''<road name="r" length="100" id="{{i}}" junction="-1" rule="{rule}">
    <planView><geometry s="0" x="0" y="{{y}}" hdg="0" length="100"><line/></geometry></planView>
    <lanes><laneSection s="0">{lanes}</laneSection></lanes></road>'''
    text = ('<?xml version="1.0"?><OpenDRIVE><header revMajor="1" revMinor="6"/>'
            + "".join(road.format(i=i, y=50 * i) for i in range(roads)) + "</OpenDRIVE>")
    path = tmp_path / "r.xodr"
    path.write_text(text)
    return path


CENTRE = '<center><lane id="0" type="none"/></center>'


def lane(i: int, kind: str = "driving", width: str = 'a="3.5" b="0" c="0" d="0"',
         mark: str = '<roadMark sOffset="0" type="solid" width="0.12"/>') -> str:
    return (f'<lane id="{i}" type="{kind}"><width sOffset="0" {width}/>{mark}</lane>')


VANISHING = 'a="1.0" b="-0.02" c="0" d="0"'  # 0 m wide at s = 50 m
STEP = 'a="3.0" b="0" c="0" d="0"'
STEEP = 'a="3.5" b="0.05" c="0" d="0"'  # 5 m wider over 100 m
CURB = '<roadMark sOffset="0" type="curb"/>'


@pytest.mark.parametrize(("lanes", "kw", "problem"), [
    (CENTRE + "<right>" + lane(-1, width=VANISHING) + "</right>", {},
     "not supported yet (a lane width that reaches 0 at s = "),
    (CENTRE + "<right>" + lane(-1) + "</right></laneSection><laneSection s=\"50\">" + CENTRE
     + "<right>" + lane(-1) + lane(-2) + "</right>", {},
     "not supported yet (lane sections with different route lanes: lanes that begin or end)"),
    (CENTRE + "<right>" + lane(-1) + "</right></laneSection><laneSection s=\"50\">" + CENTRE
     + "<right>" + lane(-1, width=STEP) + "</right>", {},
     "not supported yet (route lane 0's centre steps by 0.25 m at s = 50 m"),
    (CENTRE + "<right>" + lane(-1, width=STEEP) + "</right>", {},
     "not supported yet (lane widths or a lane offset that change this fast: route lane 0's "
     "edges' middle 2.7 mm off its centre at s = 0 m)"),
    (CENTRE + "<right>" + lane(-1) + "</right>", {"rule": "LHT"},
     "not supported yet (left-hand traffic)"),
    (CENTRE + "<right>" + lane(-1) + "</right>", {"roads": 2},
     "not supported yet (roads not linked end to end into one route: road networks)"),
    (CENTRE + "<right>" + lane(-1, "sidewalk") + "</right>", {},
     "without driving lanes right of the reference line"),
    (CENTRE + "<right>" + lane(-1, mark=CURB) + "</right>", {},
     "not supported yet (lane -1: road mark type 'curb')"),
])
def test_what_does_not_fit_the_route_is_refused_in_one_line(
        tmp_path: Path, lanes: str, kw: dict[str, object], problem: str) -> None:
    path = write(tmp_path, lanes, **kw)  # type: ignore[arg-type]
    with pytest.raises(OpenDriveError) as err:
        build_route(load_opendrive(path))
    assert problem in str(err.value)
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)
