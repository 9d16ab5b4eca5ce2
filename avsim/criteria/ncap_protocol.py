"""Euro NCAP 2023's AEB tests: which test a file names, and the protocol's points for it.

The test comes from the file: its name as the protocol writes it (the NCAP files'
`Scenario_ID` parameter, `CCRs`, `CCRs_FCW`, `CPNA-25`, `CPTAfo`, or the scenario's
`ncap.test`), read as the longest known test code it starts with (`TESTS`) and what follows
(the variant: `FCW`, `25`, `fo`). A code the 2023 protocols do not list is kept as written,
with no protocol, target or points.

The points are those of the "Euro NCAP Assessment Protocol - Safety Assist - Collision
Avoidance", Implementation 2023, Version 10.4.1, February 2024 (SA-CA 10.4.1), for the AEB
Car-to-Car tests where its text gives them as a table:

- section 3.3.1: the assessment criterion: the VUT's impact speed Vimpact for CCRs, CCRb,
  CCFhos, CCFhol; the relative impact speed Vrel_impact for CCRm; avoidance for CCFtap;
- section 3.3.2: each CCR grid point gets a colour by its impact speed, scaled
  green 1, yellow 0.75, orange 0.5, brown 0.25, red 0 (`COLOUR_SCALE`); the colour bands
  are a chart per test speed, of which the text tabulates only the 50 km/h CCRs / CCRb
  row (`CCR_BANDS_50`: green below 5 km/h, yellow below 15, orange below 30, brown below
  40, red from 40); CCRb counts as a CCRs test at 50 km/h; the points per test speed
  (`CCR_POINTS`: CCRs AEB 10-50 km/h, CCRm 30-80 km/h, CCRb 4 tests of 1 point, CCRs FCW
  55-80 km/h); the five overlaps of a test speed share its points, the 100 % overlap
  counted twice: (s[-50] + s[-75] + 2 s[100] + s[75] + s[50]) / 6 (`overlap_weight`);
- section 3.3.3: CCFtap: 1 point per combination of VUT speed 10 / 15 / 20 km/h and GVT
  speed 30 / 45 / 60 km/h where the collision is avoided (`CCFTAP_SPEEDS`);
- section 3.3.5: CCFhos and CCFhol at 50/50 and 70/70 km/h: 0.25 points for a speed
  reduction of at least 20 km/h, 0.125 for 10 to 20 km/h (`head_on_points`).

Not computed (`Points.points` None, `Points.why` says why): CCRs and CCRm at test speeds
whose colour bands SA-CA 10.4.1 gives only as a chart; CCRs FCW (the stack gives no
warning); the correction factors and the 2 km/h tolerance of sections 3.3.2.1-3.3.2.2
(they compare a laboratory's verification tests with the maker's prediction); and every
AEB VRU test (the 2023 "Assessment Protocol - Vulnerable Road User Protection" scoring
tables were not found).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

SOURCE = ("Euro NCAP Assessment Protocol - Safety Assist - Collision Avoidance, "
          "Implementation 2023, Version 10.4.1, February 2024")
C2C = "AEB C2C 2023"  # Euro NCAP Test Protocol - AEB Car-to-Car systems v4.3.1
VRU = "AEB VRU 2023"  # Euro NCAP Test Protocol - AEB/LSS VRU systems v4.5.1
SPEED_MATCH = 0.5  # [km/h] a file's speed is the protocol's test speed within this


@dataclass(frozen=True, slots=True)
class NcapKind:
    """One test of the 2023 protocols: its protocol, its target, its full name."""

    protocol: str  # `C2C` or `VRU`
    target: str  # what the target is: car, pedestrian, child pedestrian, bicyclist, ...
    name: str  # the protocol's name of the test


TESTS: dict[str, NcapKind] = {
    "CCRs": NcapKind(C2C, "car (GVT)", "Car-to-Car Rear stationary"),
    "CCRm": NcapKind(C2C, "car (GVT)", "Car-to-Car Rear moving"),
    "CCRb": NcapKind(C2C, "car (GVT)", "Car-to-Car Rear braking"),
    "CCFtap": NcapKind(C2C, "car (GVT)", "Car-to-Car Front Turn-Across-Path"),
    "CCFhos": NcapKind(C2C, "car (GVT)", "Car-to-Car Front Head-On Straight"),
    "CCFhol": NcapKind(C2C, "car (GVT)", "Car-to-Car Front Head-On Lane change"),
    "CCCscp": NcapKind(C2C, "car (GVT)", "Car-to-Car Crossing Straight Crossing Path"),
    "CPNA": NcapKind(VRU, "adult pedestrian", "Car-to-Pedestrian Nearside Adult"),
    "CPFA": NcapKind(VRU, "adult pedestrian", "Car-to-Pedestrian Farside Adult"),
    "CPNCO": NcapKind(VRU, "child pedestrian",
                      "Car-to-Pedestrian Nearside Child Obstructed"),
    "CPLA": NcapKind(VRU, "adult pedestrian", "Car-to-Pedestrian Longitudinal Adult"),
    "CPRA": NcapKind(VRU, "pedestrian", "Car-to-Pedestrian Reverse Adult/Child"),
    "CPTA": NcapKind(VRU, "adult pedestrian", "Car-to-Pedestrian Turning Adult"),
    "CBNA": NcapKind(VRU, "bicyclist", "Car-to-Bicyclist Nearside Adult"),
    "CBNAO": NcapKind(VRU, "bicyclist", "Car-to-Bicyclist Nearside Adult Obstructed"),
    "CBFA": NcapKind(VRU, "bicyclist", "Car-to-Bicyclist Farside Adult"),
    "CBLA": NcapKind(VRU, "bicyclist", "Car-to-Bicyclist Longitudinal Adult"),
    "CMRs": NcapKind(VRU, "motorcyclist", "Car-to-Motorcyclist Rear stationary"),
    "CMRb": NcapKind(VRU, "motorcyclist", "Car-to-Motorcyclist Rear braking"),
    "CMFtap": NcapKind(VRU, "motorcyclist", "Car-to-Motorcyclist Front Turn-Across-Path"),
}


@dataclass(frozen=True, slots=True)
class NcapTest:
    """A test as a file names it (module doc)."""

    written: str  # as the file writes it (`CCRs_FCW`)
    code: str  # the known test code it starts with (`CCRs`), else as written
    variant: str  # what follows the code, separators dropped (`FCW`, `25`, `fo`); "" none
    kind: NcapKind | None  # None: not a test of the 2023 protocols

    @property
    def fcw(self) -> bool:
        """The file names a forward collision warning test (`CCRs_FCW`)."""
        return "FCW" in self.variant.upper().split("_")


def parse_test(written: str) -> NcapTest:
    """The test `written` names: its longest known code prefix and the rest (module doc)."""
    codes = sorted((c for c in TESTS if written.startswith(c)), key=len, reverse=True)
    if not codes:
        return NcapTest(written, written, "", None)
    code = codes[0]
    return NcapTest(written, code, written[len(code):].lstrip("-_ "), TESTS[code])


class Colour(enum.Enum):
    """SA-CA 10.4.1 section 3.3.2's colour of a CCR grid point."""

    GREEN = "green"
    YELLOW = "yellow"
    ORANGE = "orange"
    BROWN = "brown"
    RED = "red"


# SA-CA 10.4.1 section 3.3.2, "CCRs and CCRb test with a VUT test speed of 50 km/h":
# (colour, impact speed upper bound [km/h], exclusive), in order; red beyond the last
CCR_BANDS_50: tuple[tuple[Colour, float], ...] = (
    (Colour.GREEN, 5.0), (Colour.YELLOW, 15.0), (Colour.ORANGE, 30.0), (Colour.BROWN, 40.0))
# SA-CA 10.4.1 section 3.3.2: the scaling of each colour
COLOUR_SCALE: dict[Colour, float] = {Colour.GREEN: 1.0, Colour.YELLOW: 0.75,
                                     Colour.ORANGE: 0.5, Colour.BROWN: 0.25, Colour.RED: 0.0}
# SA-CA 10.4.1 section 3.3.2, points per test speed [km/h] ("Test Speed / AEB CCRs, CCRm,
# CCRb / FCW CCRs"): CCRb has four tests at 50 km/h of 1 point each
CCR_POINTS: dict[str, dict[int, float]] = {
    "CCRs": {10: 1.0, 15: 2.0, 20: 2.0, 25: 2.0, 30: 2.0, 35: 2.0, 40: 1.0, 45: 1.0,
             50: 1.0},
    "CCRm": {30: 1.0, 35: 1.0, 40: 1.0, 45: 1.0, 50: 1.0, 55: 1.0, 60: 1.0, 65: 2.0,
             70: 2.0, 75: 2.0, 80: 2.0},
    "CCRb": {50: 1.0},
    "CCRs_FCW": {55: 1.0, 60: 1.0, 65: 1.0, 70: 1.0, 75: 1.0, 80: 1.0},
}
CCR_OVERLAPS = (-50.0, -75.0, 100.0, 75.0, 50.0)  # [%] the grid's overlaps (section 3.3.2)
CCR_BANDED_SPEED = 50  # [km/h] the test speed whose colour bands the text tabulates
# SA-CA 10.4.1 section 3.3.3: (VUT speed, GVT speed) [km/h] of the CCFtap grid, 1 point each
CCFTAP_SPEEDS = frozenset((v, g) for v in (10, 15, 20) for g in (30, 45, 60))
# SA-CA 10.4.1 section 3.3.5: (VUT speed, target speed) [km/h] of each head-on test
HEAD_ON_SPEEDS = frozenset({(50, 50), (70, 70)})
HEAD_ON_FULL, HEAD_ON_HALF = 0.25, 0.125  # points for a reduction >= 20 / >= 10 km/h
HEAD_ON_FULL_KPH, HEAD_ON_HALF_KPH = 20.0, 10.0  # [km/h] those reductions


def ccr_colour_50(v_impact_kph: float) -> Colour:
    """The colour of a 50 km/h CCRs or a CCRb test with impact speed `v_impact_kph`."""
    for colour, below in CCR_BANDS_50:
        if v_impact_kph < below:
            return colour
    return Colour.RED


def overlap_weight(overlap: float | None) -> float | None:
    """The share of a CCR test speed's points one overlap [%] carries: 2/6 for 100 %, 1/6
    for each of -50, -75, 75, 50; None for an overlap outside the grid."""
    if overlap is None:
        return None
    for grid in CCR_OVERLAPS:
        if abs(overlap - grid) <= SPEED_MATCH:
            return (2.0 if grid == 100.0 else 1.0) / 6.0
    return None


def head_on_points(reduction_kph: float) -> float:
    """CCFhos / CCFhol points for a speed reduction [km/h] (section 3.3.5)."""
    if reduction_kph >= HEAD_ON_FULL_KPH:
        return HEAD_ON_FULL
    return HEAD_ON_HALF if reduction_kph >= HEAD_ON_HALF_KPH else 0.0


@dataclass(frozen=True, slots=True)
class Outcome:
    """What one run of a test measured, in the protocol's terms."""

    test_speed_kph: float  # [km/h] the VUT's test speed
    target_speed_kph: float | None  # [km/h] the target's test speed, None: not named
    overlap: float | None  # [%] the file's overlap, None: not named
    avoided: bool
    vut_impact_kph: float  # [km/h] Vimpact: the VUT's speed at first contact (0: avoided)
    relative_impact_kph: float  # [km/h] Vrel_impact: the closing speed then (0: avoided)

    @property
    def reduction_kph(self) -> float:
        """[km/h] the test speed less Vimpact."""
        return self.test_speed_kph - self.vut_impact_kph


@dataclass(frozen=True, slots=True)
class Points:
    """A run's points: `points` of `max_points` (None: not computed, `why` says why)."""

    points: float | None
    max_points: float | None
    colour: Colour | None = None  # a CCR grid point's colour, where known
    why: str = ""  # why the points are not computed ("" when they are)


def _speed(x: float | None, grid: object) -> int | None:
    """The protocol's test speed [km/h] `x` matches in `grid` (keys or pairs' first), if any."""
    if x is None:
        return None
    near = round(x)
    return near if abs(x - near) <= SPEED_MATCH and near in grid else None  # type: ignore[operator]


def points_of(test: NcapTest, run: Outcome) -> Points:
    """The points SA-CA 10.4.1 gives `run` of `test` (module doc), or why none."""
    if test.kind is None:
        return Points(None, None, why=f"{test.written} is not a test of the 2023 protocols")
    if test.kind.protocol != C2C:
        return Points(None, None, why="the 2023 AEB VRU scoring tables were not found: "
                                      "not computed")
    if test.code in ("CCRs", "CCRm", "CCRb"):
        return _ccr(test, run)
    if test.code == "CCFtap":
        return _ccftap(run)
    if test.code in ("CCFhos", "CCFhol"):
        return _head_on(run)
    return Points(None, None, why=f"{test.code} is not among the 2023 files' tests")


def _ccr(test: NcapTest, run: Outcome) -> Points:
    """A CCRs, CCRm or CCRb grid point (section 3.3.2)."""
    table = "CCRs_FCW" if test.code == "CCRs" and test.fcw else test.code
    speed = _speed(run.test_speed_kph, CCR_POINTS[table])
    weight = 1.0 if test.code == "CCRb" else overlap_weight(run.overlap)
    if speed is None or weight is None:
        return Points(None, None, why=f"{table} has no grid point at "
                                      f"{run.test_speed_kph:g} km/h, overlap {run.overlap}")
    most = CCR_POINTS[table][speed] * weight
    if test.fcw:
        return Points(None, most, why="FCW not available: the stack gives no forward "
                                      "collision warning")
    if test.code == "CCRm" or speed != CCR_BANDED_SPEED:
        return Points(None, most, why=f"the {table} colour bands at {speed} km/h are a "
                                      "chart in SA-CA 10.4.1 3.3.2, not a table: not computed")
    colour = ccr_colour_50(run.vut_impact_kph)
    return Points(COLOUR_SCALE[colour] * most, most, colour)


def _ccftap(run: Outcome) -> Points:
    """A CCFtap combination (section 3.3.3): 1 point if avoided."""
    pair = (_speed(run.test_speed_kph, {10, 15, 20}),
            _speed(run.target_speed_kph, {30, 45, 60}))
    if pair not in CCFTAP_SPEEDS:
        return Points(None, None, why="not a CCFtap speed combination of SA-CA 10.4.1 3.3.3")
    return Points(1.0 if run.avoided else 0.0, 1.0)


def _head_on(run: Outcome) -> Points:
    """A CCFhos / CCFhol test (section 3.3.5) by its speed reduction."""
    pair = (_speed(run.test_speed_kph, {50, 70}), _speed(run.target_speed_kph, {50, 70}))
    if pair not in HEAD_ON_SPEEDS:
        return Points(None, None, why="not a head-on speed pair of SA-CA 10.4.1 3.3.5")
    return Points(head_on_points(run.reduction_kph), HEAD_ON_FULL)
