"""Tests of the speed-profile plot (`avsim.report.speed_plot`, `avsim run --plot`), on a
synthetic run.

No simulation: a `RunResult` is built from the bundled traffic_jam scenario's spec and a
short made-up log (60 s at 40 Hz): the lead car 30 m or more ahead in the ego's lane at 10 m/s, then
5 m/s, leaving for lane 1 at 50 s; a faster car in lane 1 that is never the lead. The CLI's
wiring is checked with the simulator replaced by a stand-in that returns that run.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from matplotlib import colors
from matplotlib import image as mpimg

from avsim.cli import main
from avsim.criteria.base import CriterionResult
from avsim.report import speed_plot as plot
from avsim.run.runner import RunResult, TrajectoryLog
from avsim.scenario.load import load_scenario
from planner.fsm.acc import AccMode
from planner.messages import SpeedSource

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
EXIT_BAD_INPUT = 2


def _mode_at(t: float) -> AccMode:
    return [m for start, m in MODES if t >= start][-1]


def synthetic_result(passed: bool = True) -> RunResult:
    scenario = load_scenario(TRAFFIC_JAM)
    assert [a.id for a in scenario.world.actors] == ["lead", "beside"]
    log = TrajectoryLog()
    ego_s, lead_s, beside_s = 20.0, 50.0, 120.0
    dt = 1.0 / RATE
    for i in range(round(DURATION * RATE)):
        t = i * dt
        ego_v = 9.0 if t < 30 else 4.5
        lead_v = 10.0 if t < 30 else 5.0
        log.t.append(t)
        log.speed.append(ego_v)
        log.station.append(ego_s)
        log.cross_track.append(0.2 * math.sin(t))  # wanders, well inside the band
        log.lane.append(0)
        log.speed_limit.append(50 / 3.6)
        log.acc_mode.append(_mode_at(t))
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
                     sim_time=DURATION, wall_time=1.0, log=log, recording=None)


def test_lead_speed_is_the_runs_vehicle_ahead_from_the_truth() -> None:
    """The plot draws the log's lead (`world.truth.vehicles_ahead`, tested there): a gap in
    the line where there is none."""
    result = synthetic_result()
    t = result.log.array("t")
    lead = plot.lead_speed(result)
    assert lead.shape == t.shape
    np.testing.assert_allclose(lead[t < 30], 10.0)
    np.testing.assert_allclose(lead[(t >= 30) & (t < LEAD_LEAVES)], 5.0)
    assert np.isnan(lead[t >= LEAD_LEAVES]).all()


def test_mode_runs_cover_the_run_without_gaps() -> None:
    c, t = AccMode.CRUISE, AccMode.TRAIL
    runs = plot.mode_runs([0.0, 1.0, 2.0, 3.0], [c, c, t, c])
    assert runs == [("cruise", 0.0, 2.0), ("trail", 2.0, 3.0), ("cruise", 3.0, 4.0)]
    assert plot.mode_runs([], []) == []


def test_every_acc_mode_has_its_own_colour() -> None:
    assert set(plot.MODE_COLOURS) == {m.value for m in AccMode}
    assert len(set(plot.MODE_COLOURS.values())) == len(AccMode)
    assert set(plot.SOURCE_COLOURS) == {s.value for s in SpeedSource}
    assert len(set(plot.SOURCE_COLOURS.values())) == len(SpeedSource)


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
    assert png.shape[:2] == (700, 1600)
    # each mode of the run covers a band of the plot (thousands of pixels; its legend
    # patch alone is a few hundred), the modes it never had do not appear at all
    for mode in {m.value for _, m in MODES}:
        assert _band_pixels(png, plot.MODE_COLOURS[mode]) > 5_000, mode
    for mode in set(plot.MODE_COLOURS) - {m.value for _, m in MODES}:
        assert _band_pixels(png, plot.MODE_COLOURS[mode]) < 50, mode
    # the speed-source strip: a band per source the run had (a few hundred pixels: the strip
    # is ~45 px high), none for the others
    for source in {s.value for s in SOURCES.values()}:
        assert _band_pixels(png, plot.SOURCE_COLOURS[source]) > 1_000, source
    for source in set(plot.SOURCE_COLOURS) - {s.value for s in SOURCES.values()}:
        assert _band_pixels(png, plot.SOURCE_COLOURS[source]) < 50, source


def test_figure_title_axes_and_legends() -> None:
    fig = plot.speed_profile_figure(synthetic_result(passed=False))
    ax, strip = fig.axes
    assert ax.get_title() == "traffic_jam (traffic_jam): FAIL (min_gap)"
    assert strip.get_xlabel() == "time [s]" and ax.get_ylabel() == "speed [km/h]"
    assert strip.get_ylabel() == "speed set by"
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
    assert ax.get_xlim() == pytest.approx((0.0, DURATION))


def test_an_empty_run_still_plots(tmp_path: Path) -> None:
    result = synthetic_result()
    empty = RunResult(scenario=result.scenario, criteria=[], metrics={}, sim_time=0.0,
                      wall_time=0.0, log=TrajectoryLog(), recording=None)
    path = plot.plot_speed_profile(empty, tmp_path / "empty.png")
    assert mpimg.imread(path).shape[:2] == (700, 1600)


# -- the command line -------------------------------------------------------------------------


class FakeRunner:
    """Stands in for `avsim.run.runner.Runner`: writes a recording stub, returns the
    synthetic run."""

    def __init__(self, scenario: object, recording: Path, *_args: object) -> None:
        self.scenario = scenario
        recording.write_bytes(b"rrd")

    def run(self, _progress: object = None) -> RunResult:
        return synthetic_result()


@pytest.fixture
def fake_runner(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    monkeypatch.setattr("avsim.run.runner.Runner", FakeRunner)
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
    assert mpimg.imread(fake_runner / png).shape[:2] == (700, 1600)
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
