"""Tests of the run's plot (`avsim.report.speed_plot`, `avsim run --plot`) and its margin
panels (`avsim.report.margins`), on a synthetic run.

No simulation: a `RunResult` is built from the bundled traffic_jam scenario's spec and a
short made-up log (60 s at 40 Hz): the lead car 25 m or more ahead in the ego's lane at
10 m/s while the ego does 9 m/s, then at 30 s it slows to 2 m/s and the ego to 4.5 m/s, so
the ego closes on it at 2.5 m/s (its time to collision falls under 10 s at ~41.7 s, its gap
under R157's d_min at ~49.6 s) until it leaves for lane 1 at 50 s; a faster car in lane 1
that is never the lead. The motion FSM changes lane to the left from 5 s to 9 s and starts
one to the right at 12 s that it aborts at 14 s. The CLI's wiring is checked with the
simulator replaced by a stand-in that returns that run.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from matplotlib import colors
from matplotlib import image as mpimg
from matplotlib.lines import Line2D
from numpy.typing import NDArray

from avsim.cli import main
from avsim.criteria.base import CriterionResult
from avsim.criteria.regulations import r157_min_gap
from avsim.report import dynamics, margins, marks, states
from avsim.report import speed_plot as plot
from avsim.report.states import RecordedChange
from avsim.run.recorded import recorded_changes, recorded_states
from avsim.run.runner import RunResult, TrajectoryLog
from avsim.scenario.load import load_scenario
from planner.fsm.acc import AccMode
from planner.fsm.machine import StateChange
from planner.fsm.motion import LANE_CHANGES as PLANNER_LANE_CHANGES
from planner.fsm.motion import TABLE as MOTION_TABLE
from planner.fsm.motion import Motion
from planner.messages import MACHINES, SpeedSource
from world.spec import RoadSpec, SegmentSpec
from world.truth import time_to_collision

REPO = Path(__file__).parents[3]
TRAFFIC_JAM = REPO / "scenarios" / "traffic_jam.yaml"
RATE = 40.0  # [Hz] control ticks
DURATION = 60.0  # [s]
LANE_WIDTH = 3.5  # [m] traffic_jam's
MODES = ((0.0, AccMode.CRUISE), (20.0, AccMode.TRAIL), (40.0, AccMode.BRAKE),
         (45.0, AccMode.SPEED_LIMIT))
SOURCES = {AccMode.CRUISE: SpeedSource.SET_SPEED, AccMode.TRAIL: SpeedSource.FOLLOWING,
           AccMode.BRAKE: SpeedSource.FOLLOWING, AccMode.SPEED_LIMIT: SpeedSource.LIMIT}
LEAD_LEAVES = 50.0  # [s] the lead moves to lane 1
SLOW_DOWN = 30.0  # [s] the lead slows to 2 m/s, the ego to 4.5 m/s
EGO_SPEED, LEAD_SPEED = (9.0, 4.5), (10.0, 2.0)  # [m/s] before, after SLOW_DOWN
CLOSING = EGO_SPEED[1] - LEAD_SPEED[1]  # [m/s] after SLOW_DOWN
# the motion FSM: (start [s], state, the reason of the change into it)
MOTIONS = ((0.0, Motion.LANE_KEEP, ""),
           (5.0, Motion.LANE_CHANGE_LEFT, "a slower vehicle ahead, the left lane free"),
           (9.0, Motion.LANE_KEEP, "in the target lane"),
           (12.0, Motion.LANE_CHANGE_RIGHT, "the route needs a lane to the right"),
           (14.0, Motion.LANE_KEEP, "the target lane is no longer free: abort"))
PX = (1200, 1600)  # [px] the PNG's height, width
EXIT_BAD_INPUT = 2


def _mode_at(t: float) -> AccMode:
    return [m for start, m in MODES if t >= start][-1]


def _motion_at(t: float) -> Motion:
    return [m for start, m, _ in MOTIONS if t >= start - 1e-9][-1]


def _motion_changes() -> tuple[StateChange, ...]:
    return tuple(StateChange(t, "motion", before.value, after.value, reason)
                 for (_, before, _), (t, after, reason) in itertools.pairwise(MOTIONS))


def synthetic_result(passed: bool = True) -> RunResult:
    scenario = load_scenario(TRAFFIC_JAM)
    assert [a.id for a in scenario.world.actors] == ["lead", "beside"]
    log = TrajectoryLog()
    ego_s, lead_s, beside_s = 20.0, 50.0, 120.0
    dt = 1.0 / RATE
    for i in range(round(DURATION * RATE)):
        t = i * dt
        ego_v = EGO_SPEED[t >= SLOW_DOWN]
        lead_v = LEAD_SPEED[t >= SLOW_DOWN]
        log.t.append(t)
        log.speed.append(ego_v)
        log.station.append(ego_s)
        log.cross_track.append(0.2 * math.sin(t))  # wanders, well inside the band
        log.lane.append(0)
        log.speed_limit.append(50 / 3.6)
        log.acc_mode.append(_mode_at(t))
        log.motion.append(_motion_at(t))
        log.speed_source.append(SOURCES[_mode_at(t)])
        ahead = t < LEAD_LEAVES  # then it moves to lane 1: no vehicle ahead
        log.lead_gap.append(lead_s - ego_s - 4.8 if ahead else math.nan)
        log.lead_speed.append(lead_v if ahead else math.nan)
        ego_s += ego_v * dt
        lead_s = ego_s + 30.0 if t < 1 else lead_s + lead_v * dt
        beside_s += 15.0 * dt
    criteria = [CriterionResult("no_collision", True, 0.0, 0.0, "-"),
                CriterionResult("min_gap", passed, 12.0, 14.0, "m")]
    return RunResult(scenario=scenario, criteria=criteria, metrics={"max_speed": 9.0},
                     sim_time=DURATION, wall_time=1.0, log=log, recording=None,
                     state_changes=_motion_changes())


def test_lead_speed_is_the_runs_vehicle_ahead_from_the_truth() -> None:
    """The plot draws the log's lead (`world.truth.vehicles_ahead`, tested there): a gap in
    the line where there is none."""
    result = synthetic_result()
    t = result.log.array("t")
    lead = plot.lead_speed(result)
    assert lead.shape == t.shape
    np.testing.assert_allclose(lead[t < SLOW_DOWN], 10.0)
    np.testing.assert_allclose(lead[(t >= SLOW_DOWN) & (t < LEAD_LEAVES)], 2.0)
    assert np.isnan(lead[t >= LEAD_LEAVES]).all()


def test_mode_runs_cover_the_run_without_gaps() -> None:
    c, t = AccMode.CRUISE, AccMode.TRAIL
    runs = plot.mode_runs([0.0, 1.0, 2.0, 3.0], [c, c, t, c])
    assert runs == [("cruise", 0.0, 2.0), ("trail", 2.0, 3.0), ("cruise", 3.0, 4.0)]
    assert plot.mode_runs([], []) == []


def _lab(colour: str, alpha: float = 1.0) -> NDArray[np.float64]:
    """CIE L*a*b* (D65) of `colour` drawn at `alpha` over white."""
    rgb = alpha * np.array(colors.to_rgb(colour)) + (1.0 - alpha)
    lin = np.where(rgb > 0.04045, ((rgb + 0.055) / 1.055) ** 2.4, rgb / 12.92)
    m = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                  [0.0193, 0.1192, 0.9505]])
    xyz = m @ lin / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16 / 116)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


MIN_DELTA_E = 10.0  # [-] CIE76 distance between any two bands as drawn: told apart at a glance


def _bands() -> dict[str, str]:
    """Every band's meaning -> colour, over the three tables."""
    return {**{f"mode {k}": v for k, v in plot.MODE_COLOURS.items()},
            **{f"source {k}": v for k, v in plot.SOURCE_COLOURS.items()},
            **{f"manoeuvre {k}": v for k, v in margins.MOTION_COLOURS.items()}}


def _lines() -> dict[str, str]:
    """Every line's and mark's subject -> colour (lines of one subject share its colour)."""
    subject = {"ego": "ego", "offset": "ego", "accel": "ego", "accel_2s": "ego",
               "jerk": "ego", "lead": "lead", "gap": "lead"}
    out: dict[str, str] = {}
    for table in (plot.LINES, margins.GAP_LINES, dynamics.LINES):
        for key, (_, colour, _, _) in table.items():
            name = subject.get(key, key)
            assert out.get(name, colour) == colour, name
            out[name] = colour
    return {**out, "story event": marks.EVENT_COLOUR, "fault window": marks.WINDOW_COLOUR,
            "under d_min": margins.UNDER_D_MIN}


def test_every_state_has_a_colour_of_its_own() -> None:
    """Every ACC mode, speed source and manoeuvre of the stack's enums has a band colour; no
    colour has two meanings across the figure (bands, lines, marks); the bands as drawn are
    at least MIN_DELTA_E apart."""
    assert {m.value for m in AccMode} <= set(plot.MODE_COLOURS)
    assert {s.value for s in SpeedSource} <= set(plot.SOURCE_COLOURS)
    moves = {m.value for m in Motion} - margins.NEUTRAL | {margins.ABORTED, margins.PULL_OVER}
    assert moves <= set(margins.MOTION_COLOURS)
    meanings = {**_bands(), **_lines()}
    by_colour: dict[str, list[str]] = {}
    for meaning, colour in meanings.items():
        by_colour.setdefault(colors.to_hex(colour), []).append(meaning)
    shared = {c: m for c, m in by_colour.items() if len(m) > 1}
    assert not shared, shared
    bands = list(_bands().items())
    for (a, ca), (b, cb) in itertools.combinations(bands, 2):
        delta = float(np.linalg.norm(_lab(ca, plot.BAND_ALPHA) - _lab(cb, plot.BAND_ALPHA)))
        assert delta >= MIN_DELTA_E, (a, b, delta)


def _band_pixels(png: np.ndarray, colour: str) -> int:
    """Pixels of the band colour as drawn: `colour` at BAND_ALPHA over white, +- 2/255."""
    rgb = np.array(colors.to_rgb(colour))
    blended = plot.BAND_ALPHA * rgb + (1.0 - plot.BAND_ALPHA)
    close = np.all(np.abs(png[..., :3] - blended) <= 2.0 / 255.0, axis=-1)
    return int(close.sum())


def test_plot_writes_a_png_of_the_expected_size_with_mode_bands(tmp_path: Path) -> None:
    path = tmp_path / "deep" / "traffic_jam.png"  # a directory that does not exist yet
    assert plot.plot_speed_profile(synthetic_result(passed=False), path) == path
    assert path.is_file()
    assert 20_000 <= path.stat().st_size <= 1_000_000, path.stat().st_size
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no partial file left
    png = mpimg.imread(path)
    assert png.shape[:2] == PX
    # each mode of the run covers a band of the plot (thousands of pixels; its legend
    # patch alone is a few hundred), the modes it never had do not appear at all
    for mode in {m.value for _, m in MODES}:
        assert _band_pixels(png, plot.MODE_COLOURS[mode]) > 5_000, mode
    for mode in set(plot.MODE_COLOURS) - {m.value for _, m in MODES}:
        assert _band_pixels(png, plot.MODE_COLOURS[mode]) < 50, mode
    # the speed-source strip: a band per source the run had (a few hundred pixels: the strip
    # is ~35 px high), none for the others
    for source in {s.value for s in SOURCES.values()}:
        assert _band_pixels(png, plot.SOURCE_COLOURS[source]) > 1_000, source
    for source in set(plot.SOURCE_COLOURS) - {s.value for s in SOURCES.values()}:
        assert _band_pixels(png, plot.SOURCE_COLOURS[source]) < 50, source
    # the manoeuvre strip: the lane change left (4 s of 60, ~90 px wide) and the aborted one
    # (2 s), nothing for the manoeuvres the run did not make (lane keeping has no band)
    had = {Motion.LANE_CHANGE_LEFT.value, margins.ABORTED}
    for move in had:
        assert _band_pixels(png, margins.MOTION_COLOURS[move]) > 700, move
    for move in set(margins.MOTION_COLOURS) - had:
        assert _band_pixels(png, margins.MOTION_COLOURS[move]) < 50, move


def test_figure_title_axes_and_legends() -> None:
    fig = plot.speed_profile_figure(synthetic_result(passed=False))
    ax = fig.axes[0]
    assert ax.get_title() == "traffic_jam (traffic_jam): FAIL (min_gap)"
    assert [a.get_ylabel() for a in fig.axes] == [
        "speed [km/h]", "manoeuvre", "speed set by", "accel. [m/s^2]", "jerk [m/s^3]",
        "gap [m]", "TTC [s]", "lateral offset [m]"]
    assert [a.get_xlabel() for a in fig.axes] == [""] * 7 + ["time [s]"]
    assert all(a.get_shared_x_axes().joined(ax, a) for a in fig.axes)
    assert [line.get_label() for line in ax.get_lines()] == [
        "ego speed", "lead speed", "posted limit", "set speed"]
    ego, lead, limit, set_speed = (line.get_ydata() for line in ax.get_lines())
    np.testing.assert_allclose(np.unique(ego), [4.5 * 3.6, 9.0 * 3.6])
    np.testing.assert_allclose(np.unique(limit), [50.0])
    np.testing.assert_allclose(np.unique(set_speed), [45.0])
    assert np.isnan(lead).any() and np.isfinite(lead).any()  # gaps in the lead's line
    legends = [[text.get_text() for text in legend.get_texts()] for legend in fig.legends]
    assert ["cruise", "trail", "brake", "speed limit"] in legends
    assert ["set speed", "limit", "following"] in legends
    assert ["lane change left", "lane change aborted"] in legends
    assert ax.get_xlim() == pytest.approx((0.0, DURATION))


def _ydata(line: Line2D) -> NDArray[np.float64]:
    return np.asarray(line.get_ydata(), dtype=np.float64)


def test_margin_panels_show_the_gap_ttc_and_offset() -> None:
    result = synthetic_result()
    log = result.log
    _, _, _, _, _, gap, ttc, offset = plot.speed_profile_figure(result).axes
    # the gap and d_min at the ego's speed, shaded where the gap is under d_min
    assert [line.get_label() for line in gap.get_lines()] == [
        "gap to the lead", "R157 d_min at ego speed"]
    gap_line, d_min = (_ydata(line) for line in gap.get_lines())
    np.testing.assert_array_equal(gap_line, log.array("lead_gap"))
    np.testing.assert_allclose(np.unique(d_min), [r157_min_gap(4.5), r157_min_gap(9.0)])
    assert len(gap.collections) == 1  # the shading: the gap ends under d_min (~49.6 s)
    assert gap.get_ylim()[0] == 0.0
    # the time to collision and ttc_hard
    assert [line.get_label() for line in ttc.get_lines()] == [
        "time to collision", "ttc_hard 2.5 s"]
    np.testing.assert_array_equal(_ydata(ttc.get_lines()[0]), time_to_collision(
        log.array("lead_gap"), log.array("speed"), log.array("lead_speed")))
    assert ttc.get_ylim() == (0.0, margins.TTC_VIEW)
    np.testing.assert_allclose(_ydata(ttc.get_lines()[1]), margins.TTC_HARD)
    # the true offset, and the body's bound in traffic_jam's 3.5 m lanes: +-(3.5 - 1.6) / 2
    off, upper, lower = (_ydata(line) for line in offset.get_lines()[1:])
    np.testing.assert_array_equal(off, log.array("cross_track"))
    np.testing.assert_allclose(upper, (LANE_WIDTH - 1.6) / 2)
    np.testing.assert_allclose(lower, -(LANE_WIDTH - 1.6) / 2)


def test_time_to_collision_where_the_ego_closes_on_a_lead() -> None:
    nan = math.nan
    gap = np.array([10.0, 10.0, nan, 10.0, -1.0, 12.0, 6.0])
    ego = np.array([5.0, 5.0, 5.0, 5.0, 5.0, 5.0, 0.0])
    lead = np.array([3.0, 5.0, nan, 7.0, 4.0, nan, -2.0])
    ttc = time_to_collision(gap, ego, lead)
    # closing, level, no lead, opening, overlapping (0), lead speed unknown, backing lead
    np.testing.assert_array_equal(ttc, [5.0, nan, nan, nan, 0.0, nan, 3.0])


def test_time_to_collision_of_the_synthetic_run() -> None:
    log = synthetic_result().log
    t, gap = log.array("t"), log.array("lead_gap")
    ttc = time_to_collision(gap, log.array("speed"), log.array("lead_speed"))
    closing = (t >= SLOW_DOWN) & (t < LEAD_LEAVES)
    assert np.isnan(ttc[~closing]).all()  # opening before, no lead after
    np.testing.assert_allclose(ttc[closing], gap[closing] / CLOSING)
    assert ttc[closing].max() > 20.0 and 1.5 < ttc[closing].min() < margins.TTC_HARD


def test_min_gap_is_r157s_at_each_speed() -> None:
    """R157's table: 1.0 s at 7.2 km/h (2 m/s), 1.1 s at 10 km/h, 0.1 s more every 10 km/h;
    2 m at rest."""
    speeds = np.array([0.0, 2.0, 2.5, 10.0, 30.0])
    between = 1.0 + (9.0 - 7.2) / (10.0 - 7.2) * 0.1  # [s] at 2.5 m/s = 9 km/h
    np.testing.assert_allclose(margins.min_gap(speeds), [2.0, 2.0 * 1.0, 2.5 * between,
                                                         10.0 * 1.36, 30.0 * 2.08])
    assert margins.min_gap(np.array([])).shape == (0,)


def _segment(length: float, lane_width: float) -> SegmentSpec:
    return SegmentSpec(length=length, curvature=0.0, lanes=2, oncoming_lanes=0,
                       lane_width=lane_width, shoulder=0.0)


def test_lane_margin_follows_the_segment_at_the_station() -> None:
    road = RoadSpec(segments=(_segment(100.0, 3.5), _segment(50.0, 3.0)), speed_limit=20.0)
    stations = np.array([-5.0, 0.0, 99.9, 100.0, 149.0, 400.0])
    np.testing.assert_allclose(margins.lane_margin(road, stations, 1.6),
                               [0.95, 0.95, 0.95, 0.7, 0.7, 0.7])
    empty = RoadSpec(segments=(), speed_limit=20.0)
    assert np.isnan(margins.lane_margin(empty, stations, 1.6)).all()


def test_motion_runs_tell_aborted_and_pull_over_lane_changes() -> None:
    result = synthetic_result()
    motion = recorded_states(result.log.motion)
    changes = recorded_changes(result.state_changes)
    assert margins.motion_runs(result.log.t, motion, changes) == [
        ("lane_keep", 0.0, pytest.approx(5.0)),
        ("lane_change_left", pytest.approx(5.0), pytest.approx(9.0)),
        ("lane_keep", pytest.approx(9.0), pytest.approx(12.0)),
        ("lane_change_aborted", pytest.approx(12.0), pytest.approx(14.0)),
        ("lane_keep", pytest.approx(14.0), DURATION)]
    # without the changes' reasons, a lane change is only its state
    assert [r[0] for r in margins.motion_runs(result.log.t, motion, ())] == [
        "lane_keep", "lane_change_left", "lane_keep", "lane_change_right", "lane_keep"]
    keep, right = states.LANE_KEEP, states.LANE_CHANGE_RIGHT
    pull = (RecordedChange(1.0, "motion", "lane_keep", "lane_change_right",
                           "a flat tyre: pull over"),
            RecordedChange(3.0, "acc", "cruise", "flat", "a flat tyre"),
            RecordedChange(3.0, "motion", "lane_change_right", "lane_keep",
                           "in the target lane"))
    assert margins.motion_runs([0.0, 1.0, 2.0, 3.0], [keep, right, right, keep], pull) == [
        ("lane_keep", 0.0, 1.0), ("pull_over", 1.0, 3.0), ("lane_keep", 3.0, 4.0)]
    # an abort logged by another machine, or far from the run's end, is not this one's
    other = (RecordedChange(3.0, "acc", "lane_change_right", "lane_keep", "abort"),
             RecordedChange(2.0, "motion", "lane_change_right", "lane_keep", "abort"))
    assert margins.motion_runs([0.0, 1.0, 2.0, 3.0], [keep, right, right, keep], other)[1] \
        == ("lane_change_right", 1.0, 3.0)


def test_the_recorded_motion_states_are_the_planners() -> None:
    """The report's names of the motion FSM's states are the values the planner records."""
    assert tuple(m.value for m in Motion) == states.MOTION_STATES
    assert {m.value for m in PLANNER_LANE_CHANGES} == states.LANE_CHANGES
    assert MACHINES[states.MOTION_MACHINE] is Motion


def test_the_runs_states_reach_the_report_as_recorded() -> None:
    """At the runner's boundary the stack's changes become the result JSON's records, field
    for field, and its per-tick states their values: the strip's runs are the stack's."""
    result = synthetic_result()
    changes = recorded_changes(result.state_changes)
    assert [(c.t, c.machine, c.source, c.target, c.reason) for c in changes] == [
        (c.t, c.machine, c.source, c.target, c.reason) for c in result.state_changes]
    assert all(type(c) is RecordedChange for c in changes)
    motion = recorded_states(result.log.motion)
    assert motion == [m.value for m in result.log.motion]
    assert [r[1:] for r in margins.motion_runs(result.log.t, motion, changes)] == \
        [r[1:] for r in plot.mode_runs(result.log.t, result.log.motion)]


def test_motion_reasons_are_the_motion_tables() -> None:
    """The labels read the motion FSM's logged reasons: each keyword is in exactly one row's
    (the abort's; the pull over's, into lane_change_right)."""
    for label, word in margins.MOTION_REASONS.items():
        rows = [r for r in MOTION_TABLE.rows if isinstance(r.reason, str) and word in r.reason]
        assert len(rows) == 1, (label, rows)
    pull = next(r for r in MOTION_TABLE.rows if isinstance(r.reason, str)
                and margins.MOTION_REASONS[margins.PULL_OVER] in r.reason)
    assert pull.target is Motion.LANE_CHANGE_RIGHT


def test_the_png_is_deterministic(tmp_path: Path) -> None:
    result = synthetic_result()
    first = plot.plot_speed_profile(result, tmp_path / "a.png").read_bytes()
    assert plot.plot_speed_profile(result, tmp_path / "b.png").read_bytes() == first


def test_an_empty_run_still_plots(tmp_path: Path) -> None:
    result = synthetic_result()
    empty = RunResult(scenario=result.scenario, criteria=[], metrics={}, sim_time=0.0,
                      wall_time=0.0, log=TrajectoryLog(), recording=None)
    path = plot.plot_speed_profile(empty, tmp_path / "empty.png")
    assert mpimg.imread(path).shape[:2] == PX


# -- the command line -------------------------------------------------------------------------


class FakeRunner:
    """Stands in for the `Runner` that `avsim.run.unbuilt.build_runner` builds: writes a
    recording stub, returns the synthetic run."""

    def __init__(self, scenario: object, recording: Path, *_args: object) -> None:
        self.scenario = scenario
        recording.write_bytes(b"rrd")

    def run(self, _progress: object = None) -> RunResult:
        return synthetic_result()

    def interrupt(self) -> None:
        raise AssertionError("no signal was sent")


@pytest.fixture
def fake_runner(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    monkeypatch.setattr("avsim.run.unbuilt.Runner", FakeRunner)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize(("args", "png"), [
    (["--plot"], "tmp/x.png"),  # no value: next to the recording
    (["--plot", "figs/speed.png"], "figs/speed.png"),
    (["--plot", "--no-progress"], "tmp/x.png"),  # an option after it is not its value
])
def test_run_plot_writes_the_png(fake_runner: Path, args: list[str], png: str) -> None:
    result = CliRunner().invoke(main, ["run", str(TRAFFIC_JAM), "--out", "tmp/x.rrd", *args])
    assert result.exit_code == 0, (result.output, result.exception)
    assert (fake_runner / png).is_file()
    assert mpimg.imread(fake_runner / png).shape[:2] == PX
    assert (fake_runner / "tmp" / "x.json").is_file()


def test_run_without_plot_writes_no_png(fake_runner: Path) -> None:
    result = CliRunner().invoke(main, ["run", str(TRAFFIC_JAM), "--out", "tmp/x.rrd"])
    assert result.exit_code == 0, (result.output, result.exception)
    assert not list(fake_runner.rglob("*.png"))


@pytest.mark.parametrize("where", ["is_a_directory", "below_a_file"])
def test_run_plot_bad_path_is_bad_input(fake_runner: Path, where: str) -> None:
    (fake_runner / "a_file.txt").write_text("not a directory\n", encoding="utf-8")
    bad = "." if where == "is_a_directory" else "a_file.txt/sub/x.png"
    result = CliRunner().invoke(main, ["run", str(TRAFFIC_JAM), "--out", "tmp/x.rrd",
                                       "--plot", bad])
    assert result.exit_code == EXIT_BAD_INPUT, (result.output, result.exception)
    assert result.stdout == ""
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert "--plot" in result.stderr and bad in result.stderr
    assert sorted(p.name for p in fake_runner.iterdir()) == ["a_file.txt"]  # nothing written


# -- acceleration, jerk and the story's marks --------------------------------------------------


def test_acceleration_and_jerk_of_a_known_speed() -> None:
    """A speed rising at 1 m/s^2 for 10 s then falling at 2 m/s^2: the acceleration is those
    values away from the corner, the jerk 0 there and -3 m/s^3 in mean over the corner's
    1 s window at the corner."""
    t = np.arange(0.0, 20.0, 1.0 / RATE)
    v = np.where(t < 10.0, 5.0 + t, 15.0 - 2.0 * (t - 10.0))
    a = dynamics.acceleration(t, v)
    np.testing.assert_allclose(a[(t > 1.0) & (t < 9.0)], 1.0, atol=1e-9)
    np.testing.assert_allclose(a[(t > 11.0) & (t < 19.0)], -2.0, atol=1e-9)
    j = dynamics.jerk(t, v)
    np.testing.assert_allclose(j[(t > 2.0) & (t < 8.0)], 0.0, atol=1e-9)
    corner = int(np.argmin(np.abs(t - 10.0)))
    assert j[corner] == pytest.approx(-3.0, rel=0.05)
    assert dynamics.moving_mean(np.array([0.0]), np.array([2.0]), 1.0).tolist() == [2.0]


def test_the_accel_and_jerk_panels_show_the_ego_with_iso_15622s_limits() -> None:
    result = synthetic_result()
    axes = plot.speed_profile_figure(result).axes
    accel, jerk = axes[3], axes[4]
    labels = [line.get_label() for line in accel.get_lines()]
    assert labels[:3] == ["acceleration (true, 0.25 s mean)", "acceleration, 2 s mean",
                          "ISO 15622 +-3.5 m/s^2 (2 s mean)"]
    t, v = result.log.array("t"), result.log.array("speed")
    np.testing.assert_array_equal(_ydata(accel.get_lines()[0]), dynamics.acceleration(t, v))
    levels = {float(_ydata(line)[0]) for line in accel.get_lines()[2:]}
    assert levels == {3.5, -3.5, 0.0}
    assert [line.get_label() for line in jerk.get_lines()][:2] == [
        "jerk (true, 1 s mean)", "ISO 15622 +-2.5 m/s^3"]
    np.testing.assert_array_equal(_ydata(jerk.get_lines()[0]), dynamics.jerk(t, v))
    assert {float(_ydata(line)[0]) for line in jerk.get_lines()[1:]} == {2.5, -2.5, 0.0}


def _with_story(result: RunResult) -> RunResult:
    """The synthetic run with a GNSS outage at 20 s for 4 s (ego event 0), a lead's scripted
    speed change at 30 s and an event that never fired."""
    from dataclasses import replace

    from avsim.run.story import StoryEntry
    from world.spec import EventSpec, GnssOutage, TimeTrigger

    world = replace(result.scenario.world, events=(
        EventSpec(TimeTrigger(20.0), GnssOutage(duration=4.0)),
        EventSpec(TimeTrigger(50.0), GnssOutage(duration=1.0), optional=True)))
    story = (StoryEntry("lead", 0, "speed", False, 30.0),
             StoryEntry(None, 0, "gnss_outage", False, 20.0),
             StoryEntry(None, 1, "gnss_outage", True, None))
    return RunResult(scenario=replace(result.scenario, world=world), criteria=result.criteria,
                     metrics={}, sim_time=DURATION, wall_time=1.0, log=result.log,
                     recording=None, state_changes=result.state_changes, story=story)


def test_story_events_and_fault_windows_are_marked_on_every_panel() -> None:
    result = _with_story(synthetic_result())
    assert marks.story_marks(result) == [marks.Mark(20.0, 4.0, "gnss outage"),
                                         marks.Mark(30.0, 0.0, "lead: speed")]
    fig = plot.speed_profile_figure(result)
    for ax in fig.axes:
        lines = [line for line in ax.get_lines() if line.get_color() == marks.EVENT_COLOUR]
        assert sorted(float(np.asarray(line.get_xdata())[0]) for line in lines) == [20.0, 30.0]
        spans = [p for p in ax.patches if p.get_hatch() == marks.WINDOW_HATCH]
        assert len(spans) == 1
        x0, _, width, _ = spans[0].get_extents().bounds  # in pixels: its data extent below
        assert width > 0 and x0 > 0
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert texts == ["gnss outage (4 s)", "lead: speed"]
