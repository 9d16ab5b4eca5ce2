"""OpenDRIVE road signals: read (`parse_signals`), a static speed-limit sign posting its
limit on the route from its station in its direction (`sign_limits`, `route`), and the
refusals (dynamic signals, other types, signal references, too many)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.world.map.opendrive.roads import road_xml, write
from world.frames import MPS_PER_KPH
from world.map.opendrive import OpenDriveError, load_opendrive
from world.map.opendrive.parse_signals import MAX_SIGNALS
from world.map.opendrive.route import build_route
from world.map.road import build_road_map

LINE = '<geometry s="0" x="0" y="0" hdg="0" length="1000"><line/></geometry>'
ASAM = Path("tests/data/asam_examples/exampleFilesVersion1_3/Databases")


def _file(tmp_path: Path, signals: str, road_type: str = "") -> Path:
    text = road_xml(LINE, 1000.0).replace("</lanes>", f"</lanes><signals>{signals}</signals>")
    if road_type:
        text = text.replace("<planView>", f"{road_type}<planView>")
    return write(tmp_path / "signals.xodr", text)


def _sign(s: float, kph: float, orientation: str = "+", t: float = -5.0,
          extra: str = "") -> str:
    return (f'<signal id="{s}{orientation}" s="{s}" t="{t}" zOffset="2.1" orientation='
            f'"{orientation}" dynamic="no" country="DE" type="274" subtype="-1" '
            f'value="{kph}" unit="km/h" height="0.76" width="0.76" {extra}/>')


def _postings(path: Path) -> list[tuple[float, float]]:
    road = build_road_map(build_route(load_opendrive(path)).spec)
    return [(round(p.s, 6), round(p.limit / MPS_PER_KPH, 6)) for p in road.speed_limits]


def test_signal_is_read(tmp_path: Path) -> None:
    (sig,) = load_opendrive(_file(tmp_path, _sign(100.0, 80.0))).roads[0].signals
    assert (sig.s, sig.t, sig.z_offset, sig.orientation, sig.type, sig.country) == (
        100.0, -5.0, 2.1, "+", "274", "DE")
    assert sig.speed_limit == pytest.approx(80.0 * MPS_PER_KPH)
    assert (sig.height, sig.width) == (0.76, 0.76)


def test_forward_sign_posts_its_limit_from_its_station(tmp_path: Path) -> None:
    signs = _sign(100.0, 80.0) + _sign(400.0, 60.0, "-") + _sign(600.0, 50.0, "none")
    road_type = '<type s="0" type="motorway"/>'
    # the motorway's default 130 from 0, the "+" sign's 80 from 100; the "-" sign is for
    # the other direction; the "none" sign is for both
    assert _postings(_file(tmp_path, signs, road_type)) == [(0.0, 130.0), (100.0, 80.0),
                                                           (600.0, 50.0)]


def test_sign_wins_over_a_type_record_at_its_station_and_a_later_record_wins(
        tmp_path: Path) -> None:
    road_type = ('<type s="0" type="motorway"/><type s="100" type="motorway">'
                 '<speed max="100" unit="km/h"/></type><type s="500" type="town"/>')
    got = _postings(_file(tmp_path, _sign(100.0, 80.0), road_type))
    assert got == [(0.0, 130.0), (100.0, 80.0), (500.0, 50.0)]


def test_asam_motorway_posts_120(tmp_path: Path) -> None:
    got = _postings(ASAM / "AB_RQ31_Straight.xodr")
    assert got[:2] == [(0.0, 130.0), (100.0, 120.0)]


@pytest.mark.parametrize(("signal", "problem"), [
    ('<signal id="1" s="1" t="0" orientation="+" dynamic="yes" type="1000001"/>',
     "not supported yet (dynamic signal (a traffic light) on a road)"),
    ('<signal id="1" s="1" t="0" orientation="+" dynamic="no" type="206"/>',
     "not supported yet (static signal of type '206'"),
    ('<signalReference id="1" s="1" t="0" orientation="+"/>',
     "not supported yet (signalReference)"),
    (_sign(1.0, 80.0).replace(' value="80.0"', ""), "without a value"),
    (_sign(1.0, 80.0).replace('unit="km/h"', 'unit="knots"'), "unit is not"),
    (_sign(1.0, -5.0), "value must be > 0"),
    (_sign(1.0, 80.0, "up"), "orientation is not"),
    (_sign(1.0, 80.0).replace("/>", "><dependency id='2'/></signal>"),
     "not supported yet (signal dependency)"),
])
def test_refusals(tmp_path: Path, signal: str, problem: str) -> None:
    with pytest.raises(OpenDriveError, match=None) as err:
        load_opendrive(_file(tmp_path, signal))
    assert problem in str(err.value)


def test_too_many_signals_refused_before_reading(tmp_path: Path) -> None:
    many = '<signal id="x" s="1" t="0" dynamic="maybe"/>' * (MAX_SIGNALS + 1)
    with pytest.raises(OpenDriveError, match=f"more than {MAX_SIGNALS} signals"):
        load_opendrive(_file(tmp_path, many))


def test_sloped_road_refused_naming_its_elevation_record() -> None:
    with pytest.raises(OpenDriveError) as err:
        load_opendrive(ASAM / "AB_RQ31_Crest.xodr")
    assert "elevationProfile/elevation[2]" in str(err.value)
    assert "elevation other than flat, from s = 1250 m" in str(err.value)
