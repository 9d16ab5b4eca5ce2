"""Reading .xodr files: the vendored ALKS roads, our mixed road, and refused input (each a
one-line error naming file, line and element)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from world.map.opendrive import (
    Arc,
    Line,
    Link,
    OpenDriveError,
    ParamPoly3,
    Poly3Shape,
    Spiral,
    load_opendrive,
    xmltree,
)
from world.map.opendrive.parse import MAX_FILE_BYTES
from world.map.opendrive.parse_lanes import MAX_SIDE_LANES

DATA = Path(__file__).parent / "data"
ALKS_DIR = (
    Path(__file__).parents[4] / "tests/data/alks/logical_scenarios/concrete_scenarios/road_networks"
)
ALKS = sorted(ALKS_DIR.glob("*.xodr"))
MIXED = DATA / "mixed.xodr"


def test_all_six_alks_roads_load() -> None:
    assert len(ALKS) == 6
    for path in ALKS:
        od = load_opendrive(path)
        assert (od.rev_major, od.rev_minor) == (1, 6)
        (road,) = od.roads
        geoms = road.plan_view.geometries
        assert road.length == pytest.approx(sum(g.length for g in geoms), abs=1e-9)
        assert road.plan_view.length == pytest.approx(road.length, abs=1e-9)
        assert all(isinstance(g.shape, Line | Arc | Spiral) for g in geoms)
        (section,) = road.lane_sections
        assert [ln.id for ln in section.left] == list(range(1, 9))
        assert [ln.id for ln in section.right] == list(range(-1, -9, -1))
        assert {ln.type for ln in (*section.left, *section.right)} == {"border", "stop", "driving"}
        assert road.speeds[0].road_type == "motorway" and road.speeds[0].max_speed is None


def test_alks_road_marks() -> None:
    road = load_opendrive(ALKS_DIR / "alks_road_straight.xodr").roads[0]
    section = road.lane_sections[0]
    assert [m.type for m in section.lane(-3).road_marks] == ["broken"]
    assert section.lane(-5).road_marks[0].width == pytest.approx(0.3)
    assert section.lane(-5).road_marks[0].lane_change == "none"
    assert section.lane(-1).road_marks == ()


def test_mixed_road_model() -> None:
    od = load_opendrive(MIXED)
    assert (od.rev_major, od.rev_minor, od.name) == (1, 7, "mixed")
    road = od.road("1")
    assert (road.name, road.junction, road.rule) == ("Mixed", "-1", "RHT")
    assert road.predecessor == Link("road", "7", "end")
    assert road.successor == Link("junction", "3", None)
    kinds = [type(g.shape) for g in road.plan_view.geometries]
    assert kinds == [Line, Spiral, Arc, Spiral, Arc, Spiral, Poly3Shape, ParamPoly3, ParamPoly3]
    last = road.plan_view.geometries[-1].shape
    assert isinstance(last, ParamPoly3) and last.p_range == "arcLength"
    assert [(r.s, r.max_speed, r.road_type) for r in road.speeds] == [
        (0.0, pytest.approx(50 / 3.6), "town"),
        (100.0, None, "motorway"),
    ]
    first, second = road.lane_sections
    assert (first.s, second.s) == (0.0, 80.0)
    assert first.lane(1).speed == pytest.approx(30 * 0.44704)
    assert second.lane(-1).speed == 25.0
    assert first.lane(-2).level and second.lane(-1).level is False
    mark = first.lane(1).road_marks[0]
    assert (mark.type, mark.color, mark.width, mark.lane_change) == ("solid", "white", 0.15, "none")
    assert (first.lane(1).predecessors, first.lane(1).successors) == ((), ())
    centre_mark = first.center.road_marks[0]
    assert (centre_mark.type, centre_mark.color, centre_mark.width) == ("broken", "yellow", 0.12)
    assert first.lane(-1).road_marks[0].type == "solid solid"
    with pytest.raises(KeyError):
        od.road("2")
    with pytest.raises(KeyError):
        second.lane(1)


def test_bom_and_road_length_agree() -> None:
    text = ALKS[0].read_bytes()
    assert text.startswith(b"\xef\xbb\xbf")  # the ALKS files carry a byte order mark
    road = load_opendrive(ALKS[0]).roads[0]
    x, _, _ = road.plan_view.pose(np.array([0.0]))
    assert x[0] == 0.0


def error_of(path: Path) -> str:
    with pytest.raises(OpenDriveError) as info:
        load_opendrive(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    return message[len(str(path)) :]


def test_non_numeric_attribute_names_line_path_and_attribute() -> None:
    assert error_of(DATA / "bad_number.xodr") == (
        ":9: /OpenDRIVE/road[id=0]/planView/geometry[3]/spiral: curvStart is not a number ('x')"
    )


def test_malformed_xml_names_the_line() -> None:
    assert error_of(DATA / "malformed.xodr") == ": malformed XML at line 7: mismatched tag"


def test_junction_is_not_supported_yet() -> None:
    assert error_of(DATA / "junction.xodr") == (
        ":17: /OpenDRIVE/junction[id=5]: not supported yet (junctions)"
    )


def test_missing_file() -> None:
    assert error_of(DATA / "no_such.xodr") == ": no such file"


def variant(tmp_path: Path, old: str, new: str) -> Path:
    text = MIXED.read_text()
    assert old in text
    path = tmp_path / "variant.xodr"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            '<elevation s="0" a="0" b="0"',
            '<elevation s="0" a="0" b="0.01"',
            "/elevationProfile/elevation: not supported yet (elevation other than flat, from "
            "s = 0 m)",
        ),
        (
            '<superelevation s="0" a="0"',
            '<superelevation s="0" a="0.02"',
            "/lateralProfile/superelevation: not supported yet (superelevation other than flat, "
            "from s = 0 m)",
        ),
        (
            "<objects/>",
            '<objects><tunnel id="9" s="1" length="4"/></objects>',
            "/OpenDRIVE/road[id=1]/objects/tunnel[id=9]: not supported yet (tunnel)",
        ),
        (
            "<signals></signals>",
            '<signals><signal id="4" s="1" t="0" dynamic="yes"/></signals>',
            "/OpenDRIVE/road[id=1]/signals/signal[id=4]: not supported yet (dynamic signal (a "
            "traffic light) on a road)",
        ),
        (
            '<width sOffset="0" a="2" b="0" c="0" d="0"/>',
            '<border sOffset="0" a="2" b="0" c="0" d="0"/>',
            "/right/lane[id=-2]/border: not supported yet (lane border)",
        ),
        ("<planView>", "<planView><railroad/>", "/planView/railroad: not supported yet (railroad)"),
        ('revMinor="7"', 'revMinor="3"', "/OpenDRIVE/header: not supported yet (OpenDRIVE 1.3)"),
        ('<offset x="0"', '<offset x="5"', "not supported yet (header offset other than 0)"),
        ('length="10.0">', 'length="ten">', "/geometry[1]: length is not a number ('ten')"),
        ('<arc curvature="0.02"/>', "<arc/>", "/geometry[3]/arc: missing attribute curvature"),
        ('curvEnd="0.02"', 'curvEnd="nan"', "curvEnd is not a number ('nan')"),
        ('curvEnd="0.02"', 'curvEnd="1e999"', "curvEnd is not a finite number ('1e999')"),
        (
            'bU="1" cU="0"',
            'bU="1" cU="0.1"',
            "paramPoly3: its arc length 119.985 m is not the record",
        ),
        ('y="0.0"', 'y="-2e9"', "y is beyond the limit of 1e+09 ('-2e9')"),
        ('<arc curvature="0.02"/>', '<arc curvature="2e3"/>',
         "/arc: curvature 2000 1/m is beyond 1 1/m (a radius under 1 m)"),
        ('id="-2"', 'id="-3"', "/right: lane ids are [-3, -1], not [-2, -1]"),
        ('id="-2"', 'id="two"', "id is not an integer ('two')"),
        ('<type name="solid"', '<type name="broken"', "(roadMark type differing from its"),
        ('pRange="normalized"', 'pRange="p"', "pRange is not arcLength or normalized ('p')"),
        ('length="220.0', 'length="230.0', "is not the road's length 230.0"),
        ('unit="km/h"', 'unit="kn"', "unit is not m/s, km/h or mph ('kn')"),
        (
            '<type name="solid" width="0.15"',
            '<type name="solid" width="0.3"',
            "(roadMark type width",
        ),
        ("<OpenDRIVE>", "<!DOCTYPE x [<!ENTITY a 'b'>]><OpenDRIVE>", "DOCTYPE at line 3 refused"),
        (
            "<link/>",
            '<link><successor id="x"/></link>',
            "/lane[id=1]/link/successor[id=x]: id is not an integer ('x')",
        ),
        (
            "<link/>",
            '<link><neighbor id="1"/></link>',
            "/link/neighbor[id=1]: not supported yet (neighbor)",
        ),
    ],
)
def test_refused_input(tmp_path: Path, old: str, new: str, expected: str) -> None:
    message = error_of(variant(tmp_path, old, new))
    assert expected in message
    if "DOCTYPE" not in expected:
        assert message.startswith(":") and message.split(":")[1].isdigit()


def test_a_side_with_too_many_lanes_is_refused_before_its_lanes_are_read(
        tmp_path: Path) -> None:
    """A bound on the work (the fuzzer's 10,000 duplicated lanes took 0.9 s to read and
    gave a 30 kB message): the count is checked first, and the line stays short."""
    lanes = "".join(f'<lane id="-{k}" type="shoulder" level="false"><width sOffset="0" '
                    f'a="1" b="0" c="0" d="0"/></lane>' for k in range(3, MAX_SIDE_LANES + 2))
    message = error_of(variant(tmp_path, "<right>", "<right>" + lanes))
    assert f"/right: {MAX_SIDE_LANES + 1} lanes on one side: at most {MAX_SIDE_LANES}" in message
    assert len(message) < 300


def test_file_size_limit(tmp_path: Path) -> None:
    path = tmp_path / "huge.xodr"
    with path.open("wb") as f:
        f.truncate(MAX_FILE_BYTES + 1)
    assert f"over {MAX_FILE_BYTES} bytes" in error_of(path)


def test_a_file_of_more_elements_than_the_bound_is_refused_while_it_is_parsed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The element bound stops the parse at the bound (the worst such load is timed in
    bench/bench_load.py); a smaller bound here keeps the test quick."""
    count = sum(1 for _ in ET.parse(MIXED).getroot().iter())
    monkeypatch.setattr(xmltree, "MAX_ELEMENTS", count - 1)
    assert f"more than {count - 1} elements" in error_of(MIXED)
    monkeypatch.setattr(xmltree, "MAX_ELEMENTS", count)
    load_opendrive(MIXED)


def test_a_newline_in_an_id_keeps_the_message_on_one_line(tmp_path: Path) -> None:
    path = variant(tmp_path, 'id="1" junction', 'id="a&#10;b" junction')
    path.write_text(path.read_text().replace('length="10.0">', 'length="ten">', 1))
    assert "/road[id=a b]/planView/geometry[1]: length is not a number" in error_of(path)
