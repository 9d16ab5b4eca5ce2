"""Hostile OpenDRIVE input: every file gets a road or the one-line refusal, never another
exception, and the cheap checks come before any curve is evaluated."""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest

from tests.world.map.opendrive.roads import (
    ONE_LANE,
    chained,
    geometry_xml,
    road_xml,
    straight,
    winding,
    write,
)
from world.map.opendrive import OpenDriveError, arcspline, load_opendrive, parse, shapes
from world.map.opendrive.continuity import check_continuity, check_stations
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.model import Arc, Geometry, Line, Spiral
from world.map.opendrive.route import OdrRoute, build_route
from world.map.opendrive.xmltree import parse_xml

ALKS = (Path(__file__).parents[4] / "tests/data/alks/logical_scenarios/concrete_scenarios"
        / "road_networks")


def refusal(path: Path) -> str:
    """The one-line message of the refusal of `path` (the reader and the route builder)."""
    with pytest.raises(OpenDriveError) as info:
        build_route(load_opendrive(path))
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))
    assert len(message) < len(str(path)) + 300
    return message[len(str(path)):]


def route(path: Path) -> OdrRoute:
    return build_route(load_opendrive(path))


def lanes(width: str = "3.5", section_s: str = "0", more: str = "") -> str:
    return (f'<laneSection s="{section_s}"><center><lane id="0" type="none"/></center><right>'
            f'<lane id="-1" type="driving"><width sOffset="0" a="{width}" b="0" c="0" d="0"/>'
            f'</lane></right></laneSection>{more}')


# reading


@pytest.fixture
def guard() -> Iterator[None]:
    """A hang (the unbounded read this guards against) becomes a failure after 60 s."""

    def hung(signum: int, frame: object) -> None:
        raise AssertionError("the read did not return")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(60)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


@pytest.mark.usefixtures("guard")
def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path: Path) -> None:
    fifo = tmp_path / "road.xodr"
    os.mkfifo(fifo)
    assert refusal(fifo) == ": not a regular file (a FIFO)"


@pytest.mark.usefixtures("guard")
def test_dev_zero_through_a_symlink_is_refused(tmp_path: Path) -> None:
    link = tmp_path / "road.xodr"
    link.symlink_to("/dev/zero")
    assert refusal(link) == ": not a regular file (a character device)"
    assert refusal(tmp_path) == ": not a regular file (a directory)"


def test_at_most_the_byte_bound_is_read(tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """A file over the bound is refused after reading bound + 1 bytes, whatever its size."""
    path = write(tmp_path / "road.xodr", road_xml(straight(), 100.0))
    size = path.stat().st_size
    monkeypatch.setattr(parse, "MAX_FILE_BYTES", size - 1)
    assert refusal(path) == f": over {size - 1} bytes: at most {size - 1}"
    monkeypatch.setattr(parse, "MAX_FILE_BYTES", size)
    route(path)


# degenerate roads


@pytest.mark.parametrize(("geometries", "length", "lane_xml", "expected"), [
    (straight(0.0), "0", ONE_LANE, "/road[id=1]: length must be > 0"),
    (straight(1e-9), "1e-9", ONE_LANE, "/road[id=1]: length must be > 0"[:0] + "geometry: "
     "length must be >= 0.001"),
    (straight(100.0) + geometry_xml(Geometry(100.0, 100.0, 0.0, 0.0, 0.0, Line())), "100",
     ONE_LANE, "/planView/geometry[2]: length must be >= 0.001 and <= 20000 m, got 0"),
    (straight(), "100", lanes(section_s="200"),
     "/lanes/laneSection: starts at s = 200 m, outside its road (0 .. 100 m)"),
    (straight(), "100", lanes(section_s="100"), "starts at s = 100 m, outside its road"),
    (straight(), "100", lanes() + lanes(), "/laneSection[2]: laneSection records do not "
     "ascend in s (0.0 after 0.0)"),
    (straight(), "100", lanes(width="0"), ": the route's lanes at s = 0 m are 0 m wide"),
    (straight(), "100", lanes(width="-3.5"), "/width: width a = -3.5 m is not within"),
    (straight(), "100", '<laneSection s="0"><center><lane id="0" type="none"/></center>'
     '<right><lane id="-1" type="driving"/></right></laneSection>', "missing <width>"),
    (straight(), "100", '<laneSection s="0"><center><lane id="0" type="none"/></center>'
     "</laneSection>", "without driving lanes right of the reference line"),
    (straight(), "100", "", "/lanes: missing <laneSection>"),
    (straight(), "100", '<laneOffset s="0" a="1e3" b="0" c="0" d="0"/>' + ONE_LANE,
     "/laneOffset: a = 1000 m is beyond 100 m"),
])
def test_a_degenerate_road_is_refused(tmp_path: Path, geometries: str, length: str,
                                      lane_xml: str, expected: str) -> None:
    assert expected in refusal(write(tmp_path / "road.xodr",
                                     road_xml(geometries, length, lane_xml)))


# numbers

GEOMETRY_ATTRIBUTES = ["s", "x", "y", "hdg", "length"]
HOSTILE = ["1e999", "-1e999", "NaN", "nan", "inf", "-Infinity", "1" * 5000,
           "0." + "0" * 5000 + "1", "0x10", ""]


@pytest.mark.parametrize("value", HOSTILE)
@pytest.mark.parametrize("attribute", GEOMETRY_ATTRIBUTES)
def test_a_hostile_number_in_a_record_is_refused(tmp_path: Path, attribute: str,
                                                 value: str) -> None:
    g = straight().replace(f' {attribute}="', f' {attribute}="{value}" x-="', 1)
    text = road_xml(g, 100.0)
    assert f"geometry: {attribute} is " in refusal(write(tmp_path / "road.xodr", text))


@pytest.mark.parametrize("value", HOSTILE)
@pytest.mark.parametrize(("element", "attribute"), [
    ('<arc curvature="0.01"/>', "curvature"), ('<spiral curvStart="0" curvEnd="0.01"/>',
                                               "curvEnd"),
    ('<poly3 a="0" b="0" c="0" d="0"/>', "c"),
    ('<paramPoly3 aU="0" bU="100" cU="0" dU="0" aV="0" bV="0" cV="0" dV="0"/>', "dV"),
])
def test_a_hostile_number_in_a_shape_is_refused(tmp_path: Path, element: str, attribute: str,
                                                value: str) -> None:
    shape = element.replace(f' {attribute}="', f' {attribute}="{value}" x-="', 1)
    g = geometry_xml(Geometry(0.0, 0.0, 0.0, 0.0, 100.0, Line()), shape)
    message = refusal(write(tmp_path / "road.xodr", road_xml(g, 100.0)))
    assert f": {attribute} is " in message


@pytest.mark.parametrize("value", HOSTILE)
@pytest.mark.parametrize("attribute", ["sOffset", "a", "b", "c", "d"])
def test_a_hostile_number_in_a_width_is_refused(tmp_path: Path, attribute: str,
                                                value: str) -> None:
    lane = ONE_LANE.replace(f' {attribute}="', f' {attribute}="{value}" x-="', 1)
    message = refusal(write(tmp_path / "road.xodr", road_xml(straight(), 100.0, lane)))
    assert f"/width: {attribute} is " in message


@pytest.mark.parametrize(("shape", "expected"), [
    ('<arc curvature="1.5"/>', "/arc: curvature 1.5 1/m is beyond 1 1/m"),
    ('<spiral curvStart="0" curvEnd="-2"/>', "/spiral: curvature 2 1/m is beyond 1 1/m"),
    ('<poly3 a="0" b="0" c="1e8" d="1e8"/>', "/poly3: curvature 2e+08 1/m is beyond 1 1/m"),
    ('<paramPoly3 aU="0" bU="0" cU="0" dU="0" aV="0" bV="0" cV="0" dV="0"/>',
     "/paramPoly3: curvature inf 1/m is beyond 1 1/m"),
    ('<paramPoly3 aU="0" bU="100" cU="-100" dU="0" aV="0" bV="0" cV="0" dV="0"/>',
     "/paramPoly3: curvature inf 1/m"),  # a cusp: it stops at p = 1/2 and turns back
])
def test_a_curvature_beyond_the_smallest_radius_is_refused(tmp_path: Path, shape: str,
                                                           expected: str) -> None:
    g = geometry_xml(Geometry(0.0, 0.0, 0.0, 0.0, 100.0, Line()), shape)
    assert expected in refusal(write(tmp_path / "road.xodr", road_xml(g, 100.0)))


def test_lengths_beyond_the_route_bound_are_refused(tmp_path: Path) -> None:
    assert "/road[id=1]: length must be > 0 and <= 20000 m, got 20001" in refusal(
        write(tmp_path / "a.xodr", road_xml(straight(20_001.0), 20_001.0)))
    assert "/planView/geometry: length must be >= 0.001 and <= 20000 m, got 20001" in refusal(
        write(tmp_path / "b.xodr", road_xml(straight(20_001.0), 20_000.0)))
    turn = geometry_xml(Geometry(0.0, 0.0, 0.0, 0.0, 15_000.0, Arc(1.0)))
    assert "/arc: turns more than 10000 rad" in refusal(
        write(tmp_path / "c.xodr", road_xml(turn, 15_000.0)))


def test_the_files_roads_together_are_bounded_by_the_route_length(tmp_path: Path) -> None:
    one = road_xml(straight(15_000.0), 15_000.0)
    two = one.replace("</OpenDRIVE>", one[one.index("<road"):].replace('id="1"', 'id="2"'))
    assert "/road[id=2]: the roads add up to more than 20000 m" in refusal(
        write(tmp_path / "road.xodr", two))


# planView continuity


def records_xml(geoms: list[Geometry]) -> str:
    return "".join(geometry_xml(g) for g in geoms)


@pytest.mark.parametrize(("change", "expected"), [
    ({"x": 0.42}, "/planView/geometry[2]: starts 0.42 m from where geometry[1] ends"),
    ({"y": -0.011}, "/planView/geometry[2]: starts 0.011 m from where geometry[1] ends"),
    ({"hdg": 0.002}, "/planView/geometry[2]: starts heading 0.002 rad off where geometry[1] "
                     "ends"),
    ({"s": -1.0}, "/planView/geometry[2]: starts at s = 49 m, 1 m from where geometry[1] ends"),
    ({"s": 0.02}, "/planView/geometry[2]: starts at s = 50.02 m, 0.02 m from where"),
])
def test_records_that_do_not_meet_are_refused(tmp_path: Path, change: dict[str, float],
                                              expected: str) -> None:
    a, b, c = chained([Line(), Spiral(0.0, 0.02), Arc(0.02)], 50.0)
    moved = replace(b, **{f: getattr(b, f) + d for f, d in change.items()})
    text = road_xml(records_xml([a, moved, c]), 150.0)
    assert expected in refusal(write(tmp_path / "road.xodr", text))


def test_records_within_the_tolerances_are_accepted(tmp_path: Path) -> None:
    a, b, c = chained([Line(), Spiral(0.0, 0.02), Arc(0.02)], 50.0)
    near = Geometry(c.s + 0.009, c.x + 0.007, c.y - 0.007, c.hdg + 0.0009, c.length, c.shape)
    route(write(tmp_path / "road.xodr", road_xml(records_xml([a, b, near]), 150.009)))


def test_the_projects_roads_meet_within_the_tolerances() -> None:
    """Every planView of the ALKS roads and the project's test roads that holds records
    passes the continuity check (`continuity.py`'s tolerances)."""
    files = sorted(Path(__file__).parents[4].glob("tests/**/*.xodr"))
    checked = 0
    for path in files:
        try:
            root = parse_xml(str(path), path.read_bytes())
        except OpenDriveError:
            continue  # malformed on purpose
        for road in (n for n in root.children if n.tag == "road"):
            views = [n for n in road.children if n.tag == "planView"]
            nodes = [n for n in views[0].children if n.tag == "geometry"]
            geoms = [parse._geometry(n) for n in nodes if "bad" not in path.stem]
            if len(geoms) > 1:
                pv = PlanView(tuple(geoms))
                check_stations(geoms, nodes)
                check_continuity(pv, nodes)
                checked += 1
    assert checked >= 4  # the roads of more than one record


# cheap checks first, bounded work


def test_cheap_checks_refuse_before_any_curve_is_evaluated(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """500 worst spirals whose last record's s is off, or whose first bends too much:
    refused on the numbers alone."""
    geoms = winding(500, 20.0, 1.0)
    last = geoms[-1]
    geoms[-1] = Geometry(last.s + 1.0, last.x, last.y, last.hdg, last.length, last.shape)
    text = road_xml(records_xml(geoms), 10_001.0)
    bad = road_xml(records_xml(winding(500, 20.0, 1.0)), 10_000.0).replace(
        'curvEnd="1.0"', 'curvEnd="2.0"', 1)
    calls: list[int] = []
    real = shapes.SpiralCurve.local

    def counted(self: shapes.SpiralCurve, ds: shapes.FloatArray) -> shapes.Local:
        calls.append(1)
        return real(self, ds)

    monkeypatch.setattr(shapes.SpiralCurve, "local", counted)
    assert "/geometry[500]: starts at s = 9981 m" in refusal(write(tmp_path / "a.xodr", text))
    assert calls == []
    assert "curvature 2 1/m is beyond 1 1/m" in refusal(write(tmp_path / "b.xodr", bad))
    assert calls == []


def test_the_arc_spline_work_is_bounded(tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """A road needing more pieces than the bound is refused after at most about twice the
    bound's piece evaluations (halving: a piece is split or kept)."""
    monkeypatch.setattr(arcspline, "MAX_PIECES", 200)
    text = road_xml(records_xml(winding(100, 20.0, 1.0)), 2000.0)
    calls: list[int] = []
    real = arcspline.piece_deviation

    def counted(plan_view: PlanView, piece: arcspline.ArcPiece) -> float:
        calls.append(1)
        return real(plan_view, piece)

    monkeypatch.setattr(arcspline, "piece_deviation", counted)
    assert refusal(write(tmp_path / "road.xodr", text)).startswith(
        ": the reference line needs over 200 arc-spline pieces (at s = ")
    assert 200 < len(calls) <= 2 * 201 + 100
