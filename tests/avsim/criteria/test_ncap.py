"""The Euro NCAP verdict: the protocol's tables (Safety Assist - Collision Avoidance,
Implementation 2023, v10.4.1), the test a file names, and the impact speeds from truth."""

from __future__ import annotations

from typing import Any, cast

import numpy as np
import pytest

from avsim.criteria.base import TruthSample
from avsim.criteria.declaration import RunInputs
from avsim.criteria.ncap import NCAP, NcapSetting, NcapVerdict
from avsim.criteria.ncap_protocol import (
    C2C,
    CCFTAP_SPEEDS,
    CCR_OVERLAPS,
    CCR_POINTS,
    COLOUR_SCALE,
    VRU,
    Colour,
    Outcome,
    ccr_colour_50,
    head_on_points,
    overlap_weight,
    parse_test,
    points_of,
)
from world.actors.actor_set import ActorPoses
from world.spec import ActorType

RATE = 40.0  # [Hz]
GVT_BODY = 7


# -- the protocol's tables ------------------------------------------------------------------


@pytest.mark.parametrize(("v_impact", "colour"), [
    (0.0, Colour.GREEN), (4.99, Colour.GREEN), (5.0, Colour.YELLOW), (14.99, Colour.YELLOW),
    (15.0, Colour.ORANGE), (29.99, Colour.ORANGE), (30.0, Colour.BROWN),
    (39.99, Colour.BROWN), (40.0, Colour.RED), (50.0, Colour.RED)])
def test_the_50_kph_ccr_colour_bands(v_impact: float, colour: Colour) -> None:
    assert ccr_colour_50(v_impact) is colour


def test_the_colour_scaling() -> None:
    assert [COLOUR_SCALE[c] for c in Colour] == [1.0, 0.75, 0.5, 0.25, 0.0]


def test_the_ccr_points_add_up_to_the_protocols_totals() -> None:
    # the table's "Total" row: CCRs 14, CCRm 15, CCRb 4 x 1, FCW CCRs 6
    assert sum(CCR_POINTS["CCRs"].values()) == 14.0
    assert sum(CCR_POINTS["CCRm"].values()) == 15.0
    assert sum(CCR_POINTS["CCRs_FCW"].values()) == 6.0
    assert CCR_POINTS["CCRb"] == {50: 1.0}


def test_the_overlaps_share_a_test_speed_with_100_percent_counted_twice() -> None:
    weights = [overlap_weight(o) for o in CCR_OVERLAPS]
    assert weights == pytest.approx([1 / 6, 1 / 6, 2 / 6, 1 / 6, 1 / 6])
    assert sum(w for w in weights if w is not None) == pytest.approx(1.0)
    assert overlap_weight(25.0) is None
    assert overlap_weight(None) is None


def test_the_ccftap_grid_is_nine_combinations() -> None:
    assert len(CCFTAP_SPEEDS) == 9


@pytest.mark.parametrize(("reduction", "points"), [
    (50.0, 0.25), (20.0, 0.25), (19.9, 0.125), (10.0, 0.125), (9.9, 0.0), (0.0, 0.0)])
def test_head_on_points_by_speed_reduction(reduction: float, points: float) -> None:
    assert head_on_points(reduction) == points


# -- the test a file names ------------------------------------------------------------------


@pytest.mark.parametrize(("written", "code", "variant", "protocol", "fcw"), [
    ("CCRs", "CCRs", "", C2C, False), ("CCRs_FCW", "CCRs", "FCW", C2C, True),
    ("CPNA-25", "CPNA", "25", VRU, False), ("CBNAO-50", "CBNAO", "50", VRU, False),
    ("CBNA-50", "CBNA", "50", VRU, False), ("CPTAfo", "CPTA", "fo", VRU, False),
    ("CPRA_Cm", "CPRA", "Cm", VRU, False), ("CMFtap", "CMFtap", "", VRU, False)])
def test_a_test_is_read_from_its_name(written: str, code: str, variant: str,
                                      protocol: str, fcw: bool) -> None:
    test = parse_test(written)
    assert (test.code, test.variant, test.fcw) == (code, variant, fcw)
    assert test.kind is not None and test.kind.protocol == protocol


def test_an_unknown_test_is_kept_as_written_without_points() -> None:
    test = parse_test("XYZ-1")
    assert test.kind is None and test.code == "XYZ-1"
    points = points_of(test, Outcome(20.0, None, None, True, 0.0, 0.0))
    assert points.points is None and "not a test" in points.why


# -- the points of one run ------------------------------------------------------------------


def outcome(speed: float, vimpact: float, *, target: float | None = None,
            overlap: float | None = 100.0, closing: float | None = None) -> Outcome:
    return Outcome(speed, target, overlap, vimpact == 0.0, vimpact,
                   vimpact if closing is None else closing)


def test_a_50_kph_ccrs_point_scores_its_colour_times_its_share() -> None:
    points = points_of(parse_test("CCRs"), outcome(50.0, 10.0))  # yellow, 100 % overlap
    assert points.colour is Colour.YELLOW
    assert points.points == pytest.approx(0.75 * 1.0 * 2 / 6)
    assert points.max_points == pytest.approx(2 / 6)
    avoided = points_of(parse_test("CCRs"), outcome(50.0, 0.0, overlap=-50.0))
    assert avoided.points == pytest.approx(1 / 6) == avoided.max_points


def test_a_ccrb_test_scores_by_the_50_kph_bands_whatever_its_overlap() -> None:
    points = points_of(parse_test("CCRb"), outcome(50.0, 35.0, overlap=50.0))
    assert (points.colour, points.points, points.max_points) == (Colour.BROWN, 0.25, 1.0)


@pytest.mark.parametrize(("test", "speed", "why"), [
    ("CCRs", 20.0, "chart"), ("CCRm", 50.0, "chart"), ("CCRs_FCW", 60.0, "FCW"),
    ("CPNA-25", 30.0, "VRU")])
def test_points_not_tabulated_are_not_computed(test: str, speed: float, why: str) -> None:
    points = points_of(parse_test(test), outcome(speed, 10.0, target=20.0))
    assert points.points is None and why in points.why


def test_the_ccr_maximum_is_known_where_the_colours_are_not() -> None:
    points = points_of(parse_test("CCRs"), outcome(20.0, 5.0, overlap=75.0))
    assert points.max_points == pytest.approx(2.0 / 6)


def test_ccftap_scores_avoidance_on_its_grid_only() -> None:
    tap = parse_test("CCFtap")
    assert points_of(tap, outcome(10.0, 0.0, target=30.0)).points == 1.0
    assert points_of(tap, outcome(15.0, 8.0, target=45.0)).points == 0.0
    assert points_of(tap, outcome(25.0, 0.0, target=30.0)).points is None


def test_head_on_scores_the_speed_reduction() -> None:
    hos = parse_test("CCFhos")
    assert points_of(hos, outcome(50.0, 25.0, target=50.0, closing=75.0)).points == 0.25
    assert points_of(hos, outcome(70.0, 55.0, target=70.0)).points == 0.125
    assert points_of(hos, outcome(70.0, 65.0, target=70.0)).points == 0.0
    assert points_of(hos, outcome(60.0, 0.0, target=60.0)).points is None


# -- impact speeds from the truth ------------------------------------------------------------


def poses(station: float) -> ActorPoses:
    return ActorPoses(ids=("gvt",), kinds=(ActorType.CAR,), centres=np.zeros((1, 3)),
                      yaws=np.zeros(1), half_sizes=np.array([[2.0, 0.9, 0.75]]),
                      stations=np.array([station]), offsets=np.zeros(1),
                      speeds=np.zeros(1), accels=np.zeros(1))


def sample(t: float, speed: float, gvt: float, touching: bool) -> TruthSample:
    return TruthSample(t=t, speed=speed, station=0.0, front_station=2.0,
                       tyres=np.zeros((4, 2)), tyre_stations=np.zeros(4),
                       tyre_offsets=np.zeros(4),
                       touching=frozenset({GVT_BODY}) if touching else frozenset(),
                       actors=poses(gvt))


def verdict(parameters: dict[str, int | float | bool | str] | None = None,
            setting: NcapSetting | None = None) -> NcapVerdict:
    run = RunInputs(road=cast(Any, None), car=cast(Any, None), rate=RATE, signals=(),
                    set_speed=25 / 3.6, bodies={GVT_BODY: "actor gvt"},
                    actor_bodies={GVT_BODY: "gvt"}, parameters=parameters or {})
    built = NCAP.build(setting or NcapSetting(), run)
    assert len(built) == 1 and isinstance(built[0], NcapVerdict)
    return built[0]


def drive(c: NcapVerdict, ego: list[float], gvt_rate: float, touch_at: int | None) -> None:
    """Samples at `RATE`: the ego's speeds, the target's station moving at `gvt_rate`."""
    for k, speed in enumerate(ego):
        touching = touch_at is not None and k >= touch_at
        c.update(sample(k / RATE, speed, 30.0 + gvt_rate * k / RATE, touching))


def test_the_impact_is_judged_on_the_sample_before_the_contact() -> None:
    c = verdict({"Scenario_ID": "CCRs", "Ego_speed_kph": 50.0, "Overlap": 100.0})
    ego = [10.0, 9.0, 8.0, 7.0, 2.0, 1.0]  # the onset's sample already carries the crash
    drive(c, ego, 0.0, touch_at=4)
    r = c.result()
    details = dict(r.details)
    assert r.passed is False and r.first_failure == pytest.approx(4 / RATE)
    assert r.value == pytest.approx(7.0 * 3.6)
    assert details["vut_impact_speed_kph"] == pytest.approx(7.0 * 3.6)
    assert details["speed_reduction_kph"] == pytest.approx(50.0 - 7.0 * 3.6)
    assert details["colour"] == "orange"  # 25.2 km/h at 50 km/h
    assert (details["test"], details["protocol"], details["impacted"]) == (
        "CCRs", C2C, "actor gvt")


@pytest.mark.parametrize(("rate", "closing"), [(3.0, 5.0), (-5.0, 13.0)])
def test_the_impact_speed_is_the_closing_speed_on_a_moving_target(
        rate: float, closing: float) -> None:
    c = verdict({"Scenario_ID": "CCRm", "Ego_speed_kph": 30.0, "GVT_init_speed_kph": 10.0})
    drive(c, [8.0] * 6, rate, touch_at=4)
    details = dict(c.result().details)
    assert details["impact_speed_kph"] == pytest.approx(closing * 3.6)
    assert details["vut_impact_speed_kph"] == pytest.approx(8.0 * 3.6)
    assert details["target_speed_kph"] == 10.0


def test_an_avoided_test_passes_with_no_impact() -> None:
    c = verdict({"Scenario_ID": "CCRb", "Ego_speed_kph": 50.0})
    drive(c, [10.0, 5.0, 0.0, 0.0], 0.0, touch_at=None)
    r = c.result()
    details = dict(r.details)
    assert r.passed is True and r.value == 0.0
    assert details["avoided"] is True and details["impact_speed_kph"] is None
    assert (details["points"], details["max_points"]) == (1.0, 1.0)
    assert r.as_json()["details"]["points"] == 1.0  # type: ignore[index]


def test_the_setting_names_the_test_where_the_file_does_not() -> None:
    c = verdict({"Scenario_ID": "CCRs", "Ego_speed_kph": 50.0},
                NcapSetting(test="CCFtap", speed_kph=10.0, target_speed_kph=30.0))
    assert c.test is not None and c.test.code == "CCFtap"
    assert (c.speed_kph, c.target_speed_kph) == (10.0, 30.0)


def test_the_speed_defaults_to_the_set_speed_and_no_test_fails() -> None:
    c = verdict()
    assert c.speed_kph == pytest.approx(25.0)
    drive(c, [7.0] * 3, 0.0, touch_at=None)
    r = c.result()
    assert r.passed is False and r.note is not None and "names no Euro NCAP test" in r.note


def test_an_fcw_test_says_the_warning_is_not_available() -> None:
    c = verdict({"Scenario_ID": "CCRs_FCW", "Ego_speed_kph": 60.0, "Overlap": 50.0})
    drive(c, [16.0] * 3, 0.0, touch_at=None)
    details = dict(c.result().details)
    assert str(details["fcw"]).startswith("not available")
    assert details["points"] is None and details["max_points"] == pytest.approx(1 / 6)
