"""`story`: every scripted action and ego event the scenario does not mark `optional` fires
before the run ends. A run ends early only once they all have (`avsim.run.runner`), so this
fails when the run reached its `duration` with part of its story never played: a braking
lead that never braked cannot have been tested."""

from __future__ import annotations

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration


class Story(Criterion):
    """Each required action and event (`labels`, as `story_label` names them) has fired by
    the end. Value: how many never fired; not applicable when the scenario scripts none."""

    name, unit = "story", "actions"

    def __init__(self, labels: tuple[str, ...]) -> None:
        super().__init__()
        self.labels = labels
        self.fired: frozenset[str] = frozenset()  # of the labels, those fired so far

    def update(self, sample: TruthSample) -> None:
        self.fired = sample.fired

    def result(self) -> CriterionResult:
        if not self.labels:
            return CriterionResult.not_applicable(self.name, 0.0, self.unit,
                                                  "the scenario scripts no required action")
        missing = [x for x in self.labels if x not in self.fired]
        note = "never fired: " + ", ".join(missing) if missing else None
        return CriterionResult(self.name, not missing, float(len(missing)), 0.0, self.unit,
                               None, note)


def story_label(actor: str | None, index: int) -> str:
    """How the story names an actor's action (`actor`, its index in the actor's `actions`)
    or, with `actor` None, the ego's event (its index in `events`)."""
    return f"events.{index}" if actor is None else f"actors.{actor}.actions.{index}"


STORY: Declaration[None] = Declaration(
    build=lambda _, run: [Story(run.story)], needs=frozenset({Need.STORY}), always=True)
