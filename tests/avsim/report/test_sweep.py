"""Tests of the sweep reports (`avsim.report.sweep`) on a synthetic UN R157-like cut-in grid.

No simulation: 6 initial gaps [m] (x) by 3 relative speeds [km/h] (y) made-up runs whose
`min_gap` [m] grows with the gap and shrinks with the speed; short gaps at high speed end in
contact (failed, `collisions` = 1, `min_gap` = 0), a gap under 5 m fails without one, and one
run crashed (no value).
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import warnings
from pathlib import Path

import cv2
import matplotlib as mpl
import numpy as np
import pytest
from matplotlib.patches import Rectangle

from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.report.sweep import (
    CONTACT_COLOUR,
    FAIL_COLOUR,
    FAIL_FRAME_INSET,
    NO_VALUE_COLOUR,
    heat_map,
    heat_map_figure,
    sweep_csv,
    sweep_markdown,
    sweep_rows,
)

GAP, SPEED = "actors.0.s", "actors.0.speed_kph"
GAPS = [10, 20, 30, 40, 50, 60]  # [m]
SPEEDS = [20, 40, 10]  # [km/h] deliberately not sorted: axes keep this order
CRASHED = (50, 10)  # (gap, speed) of the run that crashed
SIZE = (700, 1000)  # [px] rows, columns of the PNG
SAMPLE = 0.3  # [cell] from a cell's centre towards its corner: clear of text and frame
TOLERANCE = 4  # [0-255] per channel: PNG rounding and anti-aliasing


def _min_gap(gap: float, speed: float) -> float:
    return max(0.0, gap - 0.6 * speed)


def _outcome(gap: object, speed: object, tmp: Path, extra: dict[str, object] | None = None
             ) -> RunOutcome:
    overrides = {GAP: gap, SPEED: speed, **(extra or {})}
    job = RunJob(f"cut_in_{gap}_{speed}", "cut_in", tmp, overrides=overrides)
    if (gap, speed) == CRASHED:
        return RunOutcome(job, Status.ERROR, error="boom: ZeroDivisionError", wall_time=1.0)
    numeric = isinstance(gap, int) and isinstance(speed, int)
    value = _min_gap(gap, speed) if numeric else 5.0  # type: ignore[arg-type]
    contact = value == 0.0
    criteria: list[dict[str, object]] = [
        {"name": "no_collision", "passed": not contact, "value": float(contact),
         "threshold": 0, "unit": "contacts"},
        {"name": "min_gap", "passed": value >= 5.0, "value": value, "threshold": 5.0,
         "unit": "m"},
    ]
    result: dict[str, object] = {
        "scenario": "cut_in", "file": "cut_in.yaml", "seed": 1, "profile": "none",
        "passed": all(c["passed"] is not False for c in criteria), "sim_time": 20.0,
        "wall_time": 1.0,
        "criteria": criteria, "metrics": {"collisions": float(contact), "max_decel": None},
        "state_changes": [], "recording": "x.rrd"}
    status = Status.PASSED if result["passed"] else Status.FAILED
    return RunOutcome(job, status, result, wall_time=2.0)


def _grid(tmp: Path) -> list[RunOutcome]:
    """The runs in the order a Cartesian sweep makes them: speed outer, gap inner."""
    return [_outcome(g, s, tmp) for s, g in itertools.product(SPEEDS, GAPS)]


# --- rows, CSV, Markdown -------------------------------------------------------------------


def test_sweep_rows(tmp_path: Path) -> None:
    outcomes = _grid(tmp_path)
    rows = sweep_rows(outcomes, [GAP, SPEED], ["min_gap", "collisions", "max_decel"])
    assert len(rows) == len(outcomes)
    assert list(rows[0]) == ["run", GAP, SPEED, "passed", "status", "min_gap", "collisions",
                             "max_decel", "failed", "error"]
    by_point = {(r[GAP], r[SPEED]): r for r in rows}
    hit = by_point[10, 20]
    assert hit["passed"] is False and hit["status"] == "failed"
    assert hit["min_gap"] == 0.0 and hit["collisions"] == 1.0
    assert hit["failed"] == "no_collision min_gap" and hit["error"] == ""
    ok = by_point[60, 10]
    assert ok["passed"] is True and ok["min_gap"] == pytest.approx(54.0)
    assert ok["failed"] == "" and math.isnan(float(str(ok["max_decel"])))  # None in metrics
    crashed = by_point[CRASHED]
    assert crashed["status"] == "error" and crashed["error"] == "boom: ZeroDivisionError"
    assert math.isnan(float(str(crashed["min_gap"])))


def test_sweep_rows_missing_param_and_clashing_names(tmp_path: Path) -> None:
    rows = sweep_rows(_grid(tmp_path)[:1], ["actors.1.s"], [])
    assert rows[0]["actors.1.s"] is None
    with pytest.raises(ValueError, match="used twice: passed"):
        sweep_rows(_grid(tmp_path), [GAP], ["passed"])


def test_sweep_csv_parses_back(tmp_path: Path) -> None:
    rows = sweep_rows(_grid(tmp_path), [GAP, SPEED], ["min_gap", "collisions"])
    text = sweep_csv(rows)
    parsed = list(csv.DictReader(io.StringIO(text)))
    assert parsed and list(parsed[0]) == list(rows[0])
    assert len(parsed) == len(rows)
    for row, back in zip(rows, parsed, strict=True):
        assert back["run"] == row["run"]
        assert int(back[GAP]) == row[GAP] and int(back[SPEED]) == row[SPEED]
        assert back["passed"] == str(row["passed"]) and back["status"] == row["status"]
        value = float(str(row["min_gap"]))
        assert back["min_gap"] == "" if math.isnan(value) else float(back["min_gap"]) == value
        assert back["failed"] == row["failed"] and back["error"] == row["error"]
    assert "\r" not in text
    assert sweep_csv([]) == ""


def test_sweep_csv_quotes_commas_and_quotes(tmp_path: Path) -> None:
    outcome = _outcome('slow, "very"', "x", tmp_path)
    rows = sweep_rows([RunOutcome(outcome.job, Status.BAD_INPUT, error='bad, "value"\nhere')],
                      [GAP], ["min_gap"])
    (back,) = csv.DictReader(io.StringIO(sweep_csv(rows)))
    assert back[GAP] == 'slow, "very"' and back["error"] == 'bad, "value"\nhere'


def test_sweep_markdown(tmp_path: Path) -> None:
    rows = sweep_rows(_grid(tmp_path), [GAP, SPEED], ["min_gap"])
    lines = sweep_markdown(rows).splitlines()
    assert lines[0] == (f"| `run` | `{GAP}` | `{SPEED}` | `passed` | `status` | `min_gap` | "
                        "`failed` | `error` |")
    assert lines[1] == "|---|---|---|---|---|---|---|---|"
    assert len(lines) == 2 + len(rows)
    body = {line.split(" | ")[0]: line.split(" | ") for line in lines[2:]}
    assert body["| cut_in_10_20"][3:6] == ["**FAIL**", "failed", "0"]
    assert body["| cut_in_60_10"][3:6] == ["pass", "passed", "54"]
    assert body["| cut_in_50_10"][5] == "—"  # the crash: no value
    assert sweep_markdown([]) == ""


# --- heat map ------------------------------------------------------------------------------


class _Pixels:
    """(row, column) in the PNG of a data point (x, y) of the heat map's axes."""

    def __init__(self, outcomes: list[RunOutcome]) -> None:
        fig = heat_map_figure(outcomes, GAP, SPEED, "min_gap", title="t")
        fig.canvas.draw()  # the constrained layout places the axes as `savefig` does
        self.transform = fig.axes[0].transData

    def __call__(self, x: float, y: float) -> tuple[int, int]:
        px, py = self.transform.transform((x, y))
        return round(float(SIZE[0] - py)), round(float(px))


def _rgb(hex_or_value: str | float, vmin: float, vmax: float) -> np.ndarray:
    if isinstance(hex_or_value, str):
        rgba = mpl.colors.to_rgba(hex_or_value)
    else:
        rgba = mpl.colormaps["viridis"]((hex_or_value - vmin) / (vmax - vmin))
    return np.round(np.array(rgba[:3]) * 255.0)


def _write(tmp_path: Path) -> tuple[list[RunOutcome], np.ndarray]:
    outcomes = _grid(tmp_path)
    out = tmp_path / "maps" / "min_gap.png"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # e.g. a glyph missing from the font
        heat_map(outcomes, GAP, SPEED, "min_gap", out, title="UN R157 cut-in: min gap [m]")
    assert [p.name for p in out.parent.iterdir()] == ["min_gap.png"]  # no temporary left
    image = cv2.imread(str(out), cv2.IMREAD_COLOR)
    assert image is not None
    return outcomes, image[:, :, ::-1].astype(np.float64)  # BGR -> RGB


def test_heat_map_size_and_cell_colours(tmp_path: Path) -> None:
    outcomes, image = _write(tmp_path)
    assert image.shape[:2] == SIZE
    values = {(g, s): _min_gap(g, s) for g, s in itertools.product(GAPS, SPEEDS)
              if (g, s) != CRASHED}
    vmin, vmax = min(values.values()), max(values.values())
    pixel = _Pixels(outcomes)
    seen: dict[float, np.ndarray] = {}
    for (gap, speed), value in values.items():
        i, j = GAPS.index(gap), SPEEDS.index(speed)  # axes in order of appearance
        row, col = pixel(i - SAMPLE, j + SAMPLE)
        colour = image[row, col]
        assert np.abs(colour - _rgb(value, vmin, vmax)).max() <= TOLERANCE, (gap, speed)
        seen[value] = colour
    distinct = sorted(seen)
    for a, b in itertools.pairwise(distinct):
        assert np.abs(seen[a] - seen[b]).max() > 0, (a, b)  # different values, colours
    row, col = pixel(GAPS.index(CRASHED[0]) - SAMPLE, SPEEDS.index(CRASHED[1]) + SAMPLE)
    assert np.abs(image[row, col] - _rgb(NO_VALUE_COLOUR, 0, 1)).max() <= TOLERANCE


def _has_red(image: np.ndarray, row: int, col: int) -> bool:
    window = image[row - 3:row + 4, col - 3:col + 4].reshape(-1, 3)
    red = _rgb(FAIL_COLOUR, 0, 1)
    return bool((np.abs(window - red).max(axis=1) <= 30).any())


def test_heat_map_frames_failed_runs(tmp_path: Path) -> None:
    outcomes, image = _write(tmp_path)
    pixel = _Pixels(outcomes)
    for outcome in outcomes:
        gap, speed = outcome.job.overrides[GAP], outcome.job.overrides[SPEED]
        i, j = GAPS.index(gap), SPEEDS.index(speed)  # type: ignore[arg-type]
        row, col = pixel(i - 0.5 + FAIL_FRAME_INSET, j)  # the frame's left side
        assert _has_red(image, row, col) == (outcome.status is Status.FAILED), outcome.job.name


def test_heat_map_annotations(tmp_path: Path) -> None:
    outcomes = _grid(tmp_path)
    fig = heat_map_figure(outcomes, GAP, SPEED, "min_gap", title="t")
    ax = fig.axes[0]
    texts = {(round(t.get_position()[0]), round(t.get_position()[1])): t.get_text()
             for t in ax.texts}
    assert len(texts) == len(GAPS) * len(SPEEDS)
    assert texts[GAPS.index(10), SPEEDS.index(20)] == "0\n✗ contact"  # contact
    assert texts[GAPS.index(20), SPEEDS.index(20)] == "8"  # passed
    assert texts[GAPS.index(10), SPEEDS.index(10)] == "4\n✗"  # too close, no contact
    assert texts[GAPS.index(CRASHED[0]), SPEEDS.index(CRASHED[1])] == "error"
    assert [t.get_text() for t in ax.get_xticklabels()] == [str(g) for g in GAPS]
    assert [t.get_text() for t in ax.get_yticklabels()] == [str(s) for s in SPEEDS]
    assert ax.get_xlabel() == GAP and ax.get_ylabel() == SPEED


def test_heat_map_string_values_keep_their_order(tmp_path: Path) -> None:
    outcomes = [_outcome(g, s, tmp_path) for s in ("slow", "fast") for g in ("near", "far")]
    fig = heat_map_figure(outcomes, GAP, SPEED, "min_gap", title="t")
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["near", "far"]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["slow", "fast"]


def test_heat_map_more_than_two_swept_keys(tmp_path: Path) -> None:
    swept = [_outcome(g, s, tmp_path, {"seed": seed})
             for seed in (1, 2) for s in SPEEDS for g in GAPS]
    with pytest.raises(ValueError, match=r"other keys were swept too: seed \(2 values\)"):
        heat_map(swept, GAP, SPEED, "min_gap", tmp_path / "m.png", title="t")
    assert not (tmp_path / "m.png").exists()
    fixed = [_outcome(g, s, tmp_path, {"seed": 7}) for s in SPEEDS for g in GAPS]
    heat_map(fixed, GAP, SPEED, "min_gap", tmp_path / "m.png", title="t")  # one value: fine
    assert (tmp_path / "m.png").is_file()


def test_heat_map_bad_grids(tmp_path: Path) -> None:
    outcomes = _grid(tmp_path)
    with pytest.raises(ValueError, match="both at"):
        heat_map_figure([*outcomes, outcomes[0]], GAP, SPEED, "min_gap", title="t")
    with pytest.raises(ValueError, match=r"has no value for 'actors\.1\.s'"):
        heat_map_figure(outcomes, GAP, "actors.1.s", "min_gap", title="t")
    with pytest.raises(ValueError, match="same key"):
        heat_map_figure(outcomes, GAP, GAP, "min_gap", title="t")
    with pytest.raises(ValueError, match="no runs"):
        heat_map_figure([], GAP, SPEED, "min_gap", title="t")


EXCUSED = (20, 20)  # (gap, speed) of a run that passed with a contact UN R157 excuses


def _excused_grid(tmp: Path) -> list[RunOutcome]:
    """The grid, its run at `EXCUSED` passed with one contact, excused."""
    outcomes = _grid(tmp)
    for outcome in outcomes:
        if (outcome.job.overrides[GAP], outcome.job.overrides[SPEED]) == EXCUSED:
            assert outcome.result is not None and outcome.status is Status.PASSED
            outcome.result["metrics"] = {"collisions": 1.0, "collisions_excused": 1.0,
                                         "max_decel": 2.5}
    return outcomes


def test_sweep_rows_count_an_excused_contact(tmp_path: Path) -> None:
    rows = sweep_rows(_excused_grid(tmp_path), [GAP, SPEED],
                      ["collisions", "collisions_excused"])
    row = next(r for r in rows if (r[GAP], r[SPEED]) == EXCUSED)
    assert (row["passed"], row["collisions"], row["collisions_excused"]) == (True, 1.0, 1.0)
    table = sweep_markdown(rows)
    line = next(x for x in table.splitlines() if x.startswith("| cut_in_20_20 "))
    assert line.split(" | ")[3:7] == ["pass", "passed", "1", "1"]


def test_heat_map_marks_a_contact_a_rule_excused(tmp_path: Path) -> None:
    outcomes = _excused_grid(tmp_path)
    fig = heat_map_figure(outcomes, GAP, SPEED, "min_gap", title="t")
    texts = {(round(t.get_position()[0]), round(t.get_position()[1])): t.get_text()
             for t in fig.axes[0].texts}
    i, j = GAPS.index(EXCUSED[0]), SPEEDS.index(EXCUSED[1])
    assert texts[i, j] == "8\ncontact (excused)"
    assert texts[GAPS.index(30), SPEEDS.index(20)] == "18"  # passed, no contact
    frames = {(round(p.get_x() + 0.5 - FAIL_FRAME_INSET),
               round(p.get_y() + 0.5 - FAIL_FRAME_INSET)): mpl.colors.to_hex(p.get_edgecolor())
              for p in fig.axes[0].patches if isinstance(p, Rectangle)}
    assert frames[i, j] == CONTACT_COLOUR
    assert (GAPS.index(30), SPEEDS.index(20)) not in frames
    assert frames[GAPS.index(10), SPEEDS.index(20)] == FAIL_COLOUR
