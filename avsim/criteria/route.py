"""`completes`: the ego gets where the route goes (or stops as a flat tyre demands). It
always applies; the scenario's `reach_s` sets the station to reach (default: the route's
end less `END_MARGIN`)."""

from __future__ import annotations

import math

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration
from avsim.scenario.fields import PosFloat

END_MARGIN = 30.0  # [m] default station to reach: the route's end less this


class Completes(Criterion):
    """The ego's centre reaches `reach_s` before the end, or it stops (below `STOPPED` for
    `STOPPED_FOR`) after a flat tyre, a stop the scenario expects: value = farthest
    station [m] (the note says when the flat tyre's stop completed it)."""

    name, unit = "completes", "m"
    STOPPED, STOPPED_FOR = 0.1, 2.0  # [m/s], [s]

    def __init__(self, reach_s: float) -> None:
        super().__init__()
        self.reach_s = reach_s  # [m] station to reach
        self.farthest = -math.inf  # [m] the farthest centre station so far
        self.stopped_flat = False  # it has stood for STOPPED_FOR with a flat tyre
        self._since: float | None = None  # [s] since when it stands with a flat tyre

    def update(self, sample: TruthSample) -> None:
        self.farthest = max(self.farthest, sample.station)
        if not sample.flat or sample.speed >= self.STOPPED:
            self._since = None
            return
        self._since = sample.t if self._since is None else self._since
        self.stopped_flat |= sample.t - self._since >= self.STOPPED_FOR

    @property
    def done(self) -> bool:
        """Whether the route is completed (reached, or stopped on a flat tyre)."""
        return self.farthest >= self.reach_s or self.stopped_flat

    def result(self) -> CriterionResult:
        note = "stopped after a flat tyre" if self.stopped_flat else None
        return CriterionResult(self.name, self.done, self.farthest, self.reach_s, self.unit,
                               note=note)


COMPLETES: Declaration[float | None] = Declaration(
    build=lambda reach_s, run: [Completes(reach_s if reach_s is not None
                                          else run.road.length - END_MARGIN)],
    needs=frozenset({Need.MAP}), key="reach_s", always=True, on_route=True, setting=PosFloat,
    doc="[m] station the ego must reach, > 0, on the route. Default: the end of the route "
    "less 30 m.", example=300.0)
