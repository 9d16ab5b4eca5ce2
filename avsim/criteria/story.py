"""`story`: every scripted action and ego event the scenario does not mark `optional` fires
before the run ends. A run ends early only once they all have (`avsim.run.runner`), so this
fails when the run reached its `duration` with part of its story never played: a braking
lead that never braked cannot have been tested.

An action the OpenSCENARIO file switches off by its own configuration (an Act or Event
started only by parameter or variable values that nothing changes and that are false:
`avsim.run.story_switches`) is no part of the story: the note says so ("not applicable:
switched off by parameter X"), and with nothing else scripted the verdict is not
applicable. So is an action that only reacts to a collision, when none happened. An act
started by the run (a time to collision, a distance, a time) that never starts still
fails: the situation did not happen."""

from __future__ import annotations

from collections.abc import Mapping

from avsim.criteria.base import (
    Criterion,
    CriterionResult,
    Need,
    TruthSample,
)
from avsim.criteria.declaration import Declaration


class Story(Criterion):
    """Each required action and event (`labels`, as `story_label` names them) has fired by
    the end. Value: how many never fired; not applicable when the scenario scripts none.
    `off`: the labels of the actions the file switches off, and why (not required)."""

    name, unit = "story", "actions"

    def __init__(self, labels: tuple[str, ...], off: Mapping[str, str] | None = None) -> None:
        super().__init__()
        self.labels = labels
        self.off = dict(off or {})
        self.fired: frozenset[str] = frozenset()  # of the labels, those fired so far

    def update(self, sample: TruthSample) -> None:
        self.fired = sample.fired

    def result(self) -> CriterionResult:
        off = self._off_note()
        if not self.labels:
            return CriterionResult.not_applicable(
                self.name, 0.0, self.unit, off or "the scenario scripts no required action")
        missing = [x for x in self.labels if x not in self.fired]
        notes = ["never fired: " + ", ".join(missing)] if missing else []
        note = "; ".join(notes + ([off] if off else [])) or None
        return CriterionResult(self.name, not missing, float(len(missing)), 0.0, self.unit,
                               None, note)

    def _off_note(self) -> str | None:
        """"not applicable: switched off by parameter X (its actions)", one per reason."""
        by_why: dict[str, list[str]] = {}
        for label, why in self.off.items():
            if label not in self.fired:
                by_why.setdefault(why, []).append(label)
        return "; ".join(f"not applicable: {why} ({', '.join(labels)})"
                         for why, labels in by_why.items()) or None


def story_label(actor: str | None, index: int) -> str:
    """How the story names an actor's action (`actor`, its index in the actor's `actions`)
    or, with `actor` None, the ego's event (its index in `events`)."""
    return f"events.{index}" if actor is None else f"actors.{actor}.actions.{index}"


STORY: Declaration[None] = Declaration(
    build=lambda _, run: [Story(run.story, run.story_off)],
    needs=frozenset({Need.STORY, Need.STORY_OFF}), always=True)
