"""The reports of `avsim sweep`: a row per run (CSV, Markdown) and a heat map over two keys.

A sweep runs one scenario over the Cartesian grid of `--set key=v1,v2,...` overrides; each
job's `overrides` holds its grid point. `sweep_rows` tabulates the swept keys, the verdict
and chosen metrics (`RunOutcome.metric`: a result metric or a criterion's value) per run;
`heat_map` draws one metric over two swept keys, e.g. the UN R157 cut-in grid (initial gap
[m] x relative speed [km/h]) coloured by `min_gap` [m], with the failed runs framed in red
and marked "✗" ("✗ contact" where the ego touched something: `collisions` > 0). A contact
is always marked: a run that passed with one (a rule excused it: UN R157's unavoidable
cut-in) is framed in orange and marked "contact (excused)".

Pure but for `heat_map`'s file: no pyplot (a bare `Figure` on the Agg canvas).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib as mpl
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import Colormap, Normalize
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle
from numpy.typing import NDArray

from avsim.batch.jobs import RunOutcome, Status
from avsim.files import write_atomic
from avsim.report.suite import format_value

RUN, PASSED, STATUS, FAILED, ERROR = "run", "passed", "status", "failed", "error"  # columns
SIZE = (10.0, 7.0)  # [in] at DPI: 1000 x 700 px
DPI = 100  # [px/in]
CMAP = "viridis"  # the metric's colour map
NO_VALUE_COLOUR = "#bdbdbd"  # grey: a cell whose metric is NaN / inf, or that has no run
FAIL_COLOUR = "#d50000"  # the frame of a failed run's cell
FAIL_FRAME_WIDTH = 3.0  # [pt]
FAIL_FRAME_INSET = 0.04  # [cell] so that neighbouring frames do not merge
CONTACT_METRIC = "collisions"  # > 0: the ego touched something (every contact onset)
EXCUSED_METRIC = "collisions_excused"  # of those, the ones a rule excused
CONTACT_COLOUR = "#ff9100"  # orange: the frame of a run that passed with a contact
DARK_CELL = 0.5  # [-] relative luminance below which a cell's annotation is white
LARGE_GRID = 8  # [cells] along an axis beyond which annotations get smaller

FloatArray = NDArray[np.float64]


# --- rows, CSV, Markdown -----------------------------------------------------------------


def sweep_rows(outcomes: Sequence[RunOutcome], params: Sequence[str],
               metrics: Sequence[str]) -> list[dict[str, object]]:
    """One row per run, columns in this order: `run` (job name), each of `params` (the
    job's override, None if it has none), `passed`, `status`, each of `metrics` (a float,
    NaN if absent or the run did not finish), `failed` (the failed criteria's names,
    space-separated) and `error` (the error line of a run that did not finish, else "")."""
    columns = [RUN, *params, PASSED, STATUS, *metrics, FAILED, ERROR]
    repeated = sorted({c for c in columns if columns.count(c) > 1})
    if repeated:
        raise ValueError(f"sweep_rows: column names used twice: {', '.join(repeated)}")
    rows: list[dict[str, object]] = []
    for outcome in outcomes:
        row: dict[str, object] = {RUN: outcome.job.name}
        row.update({p: outcome.job.overrides.get(p) for p in params})
        row[PASSED] = outcome.passed
        row[STATUS] = outcome.status.value
        row.update({m: outcome.metric(m) for m in metrics})
        row[FAILED] = " ".join(str(c["name"]) for c in outcome.criteria() if c["passed"] is False)
        row[ERROR] = outcome.error or ""
        rows.append(row)
    return rows


def _csv_cell(value: object) -> object:
    """None and NaN as an empty cell; the rest as `csv` writes it (floats in full)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return value


def sweep_csv(rows: Sequence[Mapping[str, object]]) -> str:
    """The rows as CSV text (header from the first row's keys, "\\n" line ends); "" if
    there are none."""
    if not rows:
        return ""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _csv_cell(v) for k, v in row.items()})
    return buffer.getvalue()


def _md_cell(key: str, value: object) -> str:
    """A row's value as a Markdown table cell (a verdict in words)."""
    if key == PASSED:
        return "pass" if value else "**FAIL**"
    text = format_value(value) if value is not None else ""
    return " ".join(text.split()).replace("\\", "\\\\").replace("|", "\\|")


def sweep_markdown(rows: Sequence[Mapping[str, object]]) -> str:
    """The rows as a Markdown table (numbers as `format_value`, NaN as "—"); "" if none."""
    if not rows:
        return ""
    keys = list(rows[0])
    lines = ["| " + " | ".join(f"`{k}`" for k in keys) + " |",
             "|" + "|".join("---" for _ in keys) + "|"]
    lines += ["| " + " | ".join(_md_cell(k, row.get(k)) for k in keys) + " |" for row in rows]
    return "\n".join(lines) + "\n"


# --- heat map ----------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class HeatGrid:
    """A metric over two swept keys: `values[j, i]` is the run at (`xs[i]`, `ys[j]`)."""

    xs: list[object]  # the x key's values, in their order of appearance
    ys: list[object]  # the y key's values, in their order of appearance
    values: FloatArray  # (len(ys), len(xs)) the metric; NaN where absent or no run
    runs: dict[tuple[int, int], RunOutcome]  # (i, j) -> the run at that cell


def _value_key(value: object) -> str:
    """A key under which equal override values meet."""
    return repr(value)  # values may be unhashable (lists); 20 and "20" stay distinct


def _appearance(outcomes: Sequence[RunOutcome], param: str) -> list[object]:
    """The distinct values of a key over the runs, in their order of appearance."""
    seen: dict[str, object] = {}
    for outcome in outcomes:
        if param not in outcome.job.overrides:
            raise ValueError(f"heat_map: run {outcome.job.name!r} has no value for {param!r}")
        value = outcome.job.overrides[param]
        seen.setdefault(_value_key(value), value)
    return list(seen.values())


def _check_other_params(outcomes: Sequence[RunOutcome], x_param: str, y_param: str) -> None:
    """Raise if a key other than the two axes takes more than one value over the runs."""
    if x_param == y_param:
        raise ValueError(f"heat_map: x and y are the same key {x_param!r}")
    others = sorted({k for o in outcomes for k in o.job.overrides} - {x_param, y_param})
    swept = {k: len({_value_key(o.job.overrides.get(k, "<unset>")) for o in outcomes})
             for k in others}
    varied = [f"{k} ({n} values)" for k, n in swept.items() if n > 1]
    if varied:
        raise ValueError(
            f"heat_map over {x_param!r} x {y_param!r}: other keys were swept too: "
            f"{', '.join(varied)}; give a heat map only runs where they have one value")


def heat_grid(outcomes: Sequence[RunOutcome], x_param: str, y_param: str,
              metric: str) -> HeatGrid:
    """The grid of `metric` over the two keys (see `heat_map` for the errors raised)."""
    if not outcomes:
        raise ValueError("heat_map: no runs")
    xs, ys = _appearance(outcomes, x_param), _appearance(outcomes, y_param)
    _check_other_params(outcomes, x_param, y_param)
    x_index = {_value_key(v): i for i, v in enumerate(xs)}
    y_index = {_value_key(v): j for j, v in enumerate(ys)}
    values = np.full((len(ys), len(xs)), math.nan)
    runs: dict[tuple[int, int], RunOutcome] = {}
    for outcome in outcomes:
        overrides = outcome.job.overrides
        i = x_index[_value_key(overrides[x_param])]
        j = y_index[_value_key(overrides[y_param])]
        if (i, j) in runs:
            raise ValueError(f"heat_map: runs {runs[i, j].job.name!r} and "
                             f"{outcome.job.name!r} are both at {x_param}={xs[i]!r}, "
                             f"{y_param}={ys[j]!r}")
        runs[i, j] = outcome
        values[j, i] = outcome.metric(metric)
    return HeatGrid(xs, ys, values, runs)


def _norm(values: FloatArray) -> Normalize:
    """The colour scale over the finite values (0..1 when there are none)."""
    finite = values[np.isfinite(values)]
    if not finite.size:
        return Normalize(0.0, 1.0)
    return Normalize(float(finite.min()), float(finite.max()))


def _contact(outcome: RunOutcome) -> bool:
    """The run had a contact (excused or not)."""
    return outcome.metric(CONTACT_METRIC) > 0  # NaN > 0 is False


def _annotation(outcome: RunOutcome | None, value: float) -> str:
    """A cell's text: its value, marked "✗" (and "contact") for a failed run, "contact
    (excused)" for one that passed with a contact."""
    if outcome is None:
        return "no run"
    if outcome.result is None:
        return {Status.ERROR: "error", Status.INTERRUPTED: "not run"}.get(outcome.status,
                                                                          "bad input")
    text = format_value(value)
    if outcome.status is Status.FAILED:
        text += "\n✗ contact" if _contact(outcome) else "\n✗"
    elif _contact(outcome):
        text += "\ncontact (excused)"
    return text


def _frame(outcome: RunOutcome | None) -> str | None:
    """A cell's frame colour: red for a failed run, orange for one that passed with a
    contact, None for none."""
    if outcome is None:
        return None
    if outcome.status is Status.FAILED:
        return FAIL_COLOUR
    return CONTACT_COLOUR if outcome.result is not None and _contact(outcome) else None


def _text_colour(cmap: Colormap, norm: Normalize, value: float) -> str:
    """Black on a light cell, white on a dark one (Rec. 601 luma against `DARK_CELL`)."""
    if not math.isfinite(value):
        return "black"
    r, g, b, _ = cmap(float(norm(value)))
    return "black" if 0.299 * r + 0.587 * g + 0.114 * b > DARK_CELL else "white"


def _annotate(ax: Axes, grid: HeatGrid, cmap: Colormap, norm: Normalize) -> None:
    """The value of each cell, a red frame and "✗" on the cells of failed runs, an orange
    frame and "contact (excused)" on those of runs that passed with a contact."""
    size = 11 if max(len(grid.xs), len(grid.ys)) <= LARGE_GRID else 7
    for j in range(len(grid.ys)):
        for i in range(len(grid.xs)):
            outcome = grid.runs.get((i, j))
            value = float(grid.values[j, i])
            ax.text(i, j, _annotation(outcome, value), ha="center", va="center",
                    fontsize=size, color=_text_colour(cmap, norm, value), zorder=3)
            colour = _frame(outcome)
            if colour is not None:
                side = 1.0 - 2.0 * FAIL_FRAME_INSET
                ax.add_patch(Rectangle((i - 0.5 + FAIL_FRAME_INSET, j - 0.5 + FAIL_FRAME_INSET),
                                       side, side, fill=False, edgecolor=colour,
                                       linewidth=FAIL_FRAME_WIDTH, zorder=2))


def heat_map_figure(outcomes: Sequence[RunOutcome], x_param: str, y_param: str, metric: str,
                    *, title: str) -> Figure:
    """The figure of `heat_map`, not yet written."""
    grid = heat_grid(outcomes, x_param, y_param, metric)
    cmap = mpl.colormaps[CMAP].with_extremes(bad=NO_VALUE_COLOUR)
    norm = _norm(grid.values)
    fig = Figure(figsize=SIZE, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    image = ax.imshow(np.ma.masked_invalid(grid.values), cmap=cmap, norm=norm,
                      origin="lower", aspect="auto", interpolation="nearest")
    _annotate(ax, grid, cmap, norm)
    ax.set_xticks(range(len(grid.xs)), labels=[format_value(v) for v in grid.xs])
    ax.set_yticks(range(len(grid.ys)), labels=[format_value(v) for v in grid.ys])
    ax.set_xlabel(x_param)
    ax.set_ylabel(y_param)
    ax.set_title(title)
    fig.colorbar(image, ax=ax, label=metric)
    fig.legend(handles=[
        Patch(facecolor="none", edgecolor=FAIL_COLOUR, linewidth=FAIL_FRAME_WIDTH,
              label='failed run (✗; "contact": collisions > 0)'),
        Patch(facecolor="none", edgecolor=CONTACT_COLOUR, linewidth=FAIL_FRAME_WIDTH,
              label="passed with a contact a rule excused"),
        Patch(facecolor=NO_VALUE_COLOUR, label="no value (not finite, or did not finish)"),
    ], loc="outside lower center", ncols=3, fontsize="small")
    return fig


def heat_map(outcomes: Sequence[RunOutcome], x_param: str, y_param: str, metric: str,
             out: Path, *, title: str) -> None:
    """Write a PNG (`SIZE` at `DPI`) of `metric` over the swept keys `x_param` x `y_param`.

    Each cell is one run, coloured by the metric and annotated with its value (`format_value`);
    failed runs are framed in red and marked "✗" ("✗ contact" if `collisions` > 0), runs
    that passed with a contact (a rule excused it) framed in orange and marked "contact
    (excused)"; cells
    with no finite value (a run that did not finish, an absent metric, inf) are grey. Axes
    keep the values' order of appearance in the runs (numbers or strings). `out` appears
    whole (through a temporary file beside it); its directory is made.

    Raises ValueError if a run lacks either key, two runs share a cell, there are no runs,
    or another key takes more than one value over the runs (a grid of more than 2 keys).
    """
    fig = heat_map_figure(outcomes, x_param, y_param, metric, title=title)
    png = io.BytesIO()
    fig.savefig(png, format="png", dpi=DPI)
    write_atomic(out, png.getvalue())
