"""`ncap`: the Euro NCAP 2023 AEB verdict of a run: avoided or not, the impact speeds, the
speed reduction and the protocol's points, from the truth only.

The test and its set-up come from the file (never from the simulator's objects): the
scenario's `ncap` setting, else the OpenSCENARIO file's own parameters as the Euro NCAP
files declare them: the test `Scenario_ID` (`avsim.criteria.ncap_protocol.parse_test`), the
VUT's test speed `Ego_speed_kph` (else the driver's set speed), the target's speed
`GVT_init_speed_kph`, `Target_finalSpeed_kph` or `VRU_finalSpeed_kph` (else the
target's `_GVT_speed` [m/s]), the overlap `Overlap` [%].

The impact is the ego's first contact onset with any body (a target, an obstruction, a
kerb): the test is avoided when there is none. At the impact, from the last sample before
the onset (at most one criteria period earlier: the sample at the onset may already carry
the crash's impulse):

- Vimpact [km/h]: the ego's speed (its magnitude: the reverse tests back into the target);
- the impact speed Vrel_impact [km/h]: the closing speed along the ego's route, the ego's
  speed less the rate of the touched actor's station on the route over the period before
  (a crossing target adds nothing, an oncoming one its speed; a static body is at rest);
- the speed reduction [km/h]: the test speed less Vimpact.

The verdict passes when the test is avoided; its value is the impact speed (0 when
avoided). Its `details` carry the test, the speeds, the FCW state (a test the file names
an FCW test: "not available", the stack gives no warning) and the points
(`ncap_protocol.points_of`), which `avsim suite` sums into the scorecard
(`avsim.report.ncap`). A contact is still counted and judged by `no_collision`: the NCAP
verdict is in addition.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated

from pydantic import Field

from avsim.criteria.base import Criterion, CriterionResult, Need, TruthSample
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.criteria.ncap_protocol import (
    SOURCE,
    NcapTest,
    Outcome,
    parse_test,
    points_of,
)
from avsim.scenario.fields import FormatModel, NonNegFloat, PosFloat
from world.frames import to_kph

TEST_PARAMETER = "Scenario_ID"  # the NCAP files' name of the test
SPEED_PARAMETER = "Ego_speed_kph"  # [km/h] their VUT test speed
OVERLAP_PARAMETER = "Overlap"  # [%] their overlap
TARGET_SPEED_PARAMETERS = ("GVT_init_speed_kph", "Target_finalSpeed_kph",
                           "VRU_finalSpeed_kph")  # [km/h] their target's speed, by test
TARGET_SPEED_MS_PARAMETER = "_GVT_speed"  # [m/s] the head-on tests' target speed
MAX_TEST_NAME = 40  # [characters] a test's name

TestName = Annotated[str, Field(min_length=1, max_length=MAX_TEST_NAME,
                                pattern=r"^[A-Za-z0-9_\-]+$")]
Overlap = Annotated[float, Field(ge=-100.0, le=100.0)]


class NcapSetting(FormatModel):
    """The `ncap` setting: the test's set-up where the file's parameters do not give it."""

    test: TestName | None = Field(
        default=None, description="the Euro NCAP test as the protocol names it (`CCRs`, "
        "`CCRs_FCW`, `CPNA-25`), 1 to 40 letters, digits, `_`, `-`. Default: the file's "
        "`Scenario_ID` parameter")
    speed_kph: PosFloat | None = Field(
        default=None, description="[km/h] the VUT's test speed, > 0. Default: the file's "
        "`Ego_speed_kph` parameter, else the driver's set speed")
    target_speed_kph: NonNegFloat | None = Field(
        default=None, description="[km/h] the target's test speed, >= 0. Default: the "
        "file's `GVT_init_speed_kph`, `Target_finalSpeed_kph` or `VRU_finalSpeed_kph` "
        "parameter, else none")
    overlap: Overlap | None = Field(
        default=None, description="[%] the overlap, -100 to 100. Default: the file's "
        "`Overlap` parameter, else none")


def _number(parameters: Mapping[str, object], name: str) -> float | None:
    """The file's parameter `name` as a number, None when absent or not a number."""
    value = parameters.get(name)
    if isinstance(value, bool) or value is None:
        return None
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None


def _target_speed(parameters: Mapping[str, object]) -> float | None:
    """[km/h] the target's speed as the file's parameters give it (module doc)."""
    for name in TARGET_SPEED_PARAMETERS:
        if (x := _number(parameters, name)) is not None:
            return x
    ms = _number(parameters, TARGET_SPEED_MS_PARAMETER)
    return None if ms is None else to_kph(ms)


class NcapVerdict(Criterion):
    """The Euro NCAP verdict of the run (module doc)."""

    name, unit = "ncap", "km/h"

    def __init__(self, test: NcapTest | None, speed_kph: float,
                 target_speed_kph: float | None, overlap: float | None,
                 bodies: Mapping[int, str], actors: Mapping[int, str]) -> None:
        super().__init__()
        self.test = test  # None: the file names none
        self.speed_kph = speed_kph  # [km/h] the VUT's test speed
        self.target_speed_kph = target_speed_kph  # [km/h]
        self.overlap = overlap  # [%]
        self.bodies = bodies  # body id -> what it is
        self.actors = actors  # NPC body id -> actor id
        self.impact: tuple[float, str, float, float] | None = None  # (t [s], what,
        #   Vimpact [m/s], closing speed [m/s]) at the first contact onset
        self._speed: float | None = None  # [m/s] the ego's speed in the last sample
        self._t: float | None = None  # [s] the last sample's time
        self._stations: dict[str, float] = {}  # [m] actor id -> station, last sample
        self._rates: dict[str, float] = {}  # [m/s] actor id -> station rate before it
        self._touching: frozenset[int] = frozenset()

    def update(self, sample: TruthSample) -> None:
        new = sample.touching - self._touching
        self._touching = sample.touching
        if new and self.impact is None:
            body = min(new)
            speed = sample.speed if self._speed is None else self._speed
            actor = self.actors.get(body)
            rate = self._rates.get(actor, 0.0) if actor is not None else 0.0
            self.impact = (sample.t, self.bodies.get(body, f"body {body}"), abs(speed),
                           abs(speed - rate))
        self._watch(sample)

    def _watch(self, sample: TruthSample) -> None:
        """Keep the ego's speed and each actor's station rate for the next sample."""
        poses = sample.actors
        if poses is not None:
            stations = {i: float(s) for i, s in zip(poses.ids, poses.stations, strict=True)}
            if self._t is not None and sample.t > self._t:
                dt = sample.t - self._t
                self._rates = {i: (s - self._stations[i]) / dt for i, s in stations.items()
                               if i in self._stations}
            self._stations = stations
        self._speed, self._t = sample.speed, sample.t

    def outcome(self) -> Outcome:
        """The run in the protocol's terms."""
        vut, closing = (0.0, 0.0) if self.impact is None else self.impact[2:]
        return Outcome(self.speed_kph, self.target_speed_kph, self.overlap,
                       self.impact is None, to_kph(vut), to_kph(closing))

    def result(self) -> CriterionResult:
        run = self.outcome()
        test = self.test or parse_test("unknown")
        points = points_of(test, run)
        hit = self.impact
        details: list[tuple[str, str | float | bool | None]] = [
            ("test", test.code), ("variant", test.variant), ("scenario_id", test.written),
            ("protocol", test.kind.protocol if test.kind else None),
            ("target", test.kind.target if test.kind else None),
            ("test_speed_kph", run.test_speed_kph),
            ("target_speed_kph", run.target_speed_kph), ("overlap", run.overlap),
            ("avoided", run.avoided),
            ("impact_t", None if hit is None else hit[0]),
            ("impacted", None if hit is None else hit[1]),
            ("impact_speed_kph", None if hit is None else run.relative_impact_kph),
            ("vut_impact_speed_kph", None if hit is None else run.vut_impact_kph),
            ("speed_reduction_kph", None if hit is None else run.reduction_kph),
            ("fcw", "not available: the stack gives no forward collision warning"
             if test.fcw else None),
            ("colour", points.colour.value if points.colour else None),
            ("points", points.points), ("max_points", points.max_points),
            ("points_note", points.why or None), ("source", SOURCE)]
        if hit is None:
            note = f"{test.written} at {run.test_speed_kph:g} km/h: avoided"
        else:
            note = (f"{test.written} at {run.test_speed_kph:g} km/h: {hit[1]} at "
                    f"{hit[0]:.2f} s, impact {run.relative_impact_kph:.1f} km/h, Vimpact "
                    f"{run.vut_impact_kph:.1f} km/h, reduction {run.reduction_kph:.1f} km/h")
        if self.test is None:
            note = "the file names no Euro NCAP test (no Scenario_ID parameter, no " \
                   f"ncap.test); {note}"
        return CriterionResult(self.name, run.avoided and self.test is not None,
                               run.relative_impact_kph, 0.0, self.unit,
                               None if hit is None else hit[0], note, tuple(details))


def _ncap(setting: NcapSetting, run: RunInputs) -> list[Criterion]:
    """The verdict of the setting, its gaps filled from the file's parameters."""
    params = run.parameters
    written = setting.test or params.get(TEST_PARAMETER)
    speed = setting.speed_kph or _number(params, SPEED_PARAMETER) or to_kph(run.set_speed)
    target = setting.target_speed_kph if setting.target_speed_kph is not None \
        else _target_speed(params)
    overlap = setting.overlap if setting.overlap is not None \
        else _number(params, OVERLAP_PARAMETER)
    test = parse_test(str(written)) if written else None
    return [NcapVerdict(test, speed, target, overlap, run.bodies, run.actor_bodies)]


NCAP: Declaration[NcapSetting] = Declaration(
    build=_ncap,
    needs=frozenset({Need.BODIES, Need.ACTOR_BODIES, Need.ACTORS, Need.PARAMETERS,
                     Need.SET_SPEED}),
    key="ncap", setting=NcapSetting,
    doc="`{test, speed_kph, target_speed_kph, overlap}` (each optional: the file's "
    "parameters `Scenario_ID`, `Ego_speed_kph`, ... fill the gaps): the Euro NCAP 2023 AEB "
    "verdict, criterion `ncap`: passes when the test is avoided (no contact); value: the "
    "impact speed [km/h]; its details: Vimpact, the speed reduction, the protocol's "
    "points where Euro NCAP tabulates them (docs/ncap.md). `--criteria ncap` for an "
    "OpenSCENARIO file. Default: off.",
    example={"test": "CCRs", "speed_kph": 20.0})
