"""The registry: every criterion a scenario can have, and how a run gets its set.

`DECLARATIONS` lists each criterion's declaration (`avsim.criteria.declaration`), in the
order of a run's results: first the criteria that always apply, then those a scenario
adds under `criteria:`. The scenario format's `criteria:` section (`avsim.scenario.model`),
its JSON Schema and its validation are made from it; `build_criteria` makes a run's set
from the scenario's validated settings and what the run offers (`RunInputs`), and the set
says what its samples must carry (`CriteriaSet.needs`).

To add a criterion: write its module (its class and a `Declaration`) and add one line
below.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from avsim.criteria.base import CriteriaSet, Criterion, Need
from avsim.criteria.collision import NO_COLLISION
from avsim.criteria.comfort import COMFORT
from avsim.criteria.declaration import Declaration, RunInputs
from avsim.criteria.following import FOLLOWING_GAP, MIN_GAP, RESUME_WITHIN, STANDSTILL_GAP
from avsim.criteria.jerk import MAX_JERK
from avsim.criteria.lane import LANE_CHANGE, TYRES_IN_LANE
from avsim.criteria.ncap import NCAP
from avsim.criteria.right_of_way import MAX_WAIT_WITH_RIGHT_OF_WAY
from avsim.criteria.road_rules import CROSSWALKS, RED_LIGHTS, SPEED_BUMPS, STOP_SIGNS
from avsim.criteria.route import COMPLETES, MINIMUM_RISK_STOP
from avsim.criteria.speed import MAX_DECEL, SPEED_LIMIT
from avsim.criteria.story import STORY

DECLARATIONS: tuple[Declaration[Any], ...] = (
    # always
    NO_COLLISION,
    TYRES_IN_LANE,
    SPEED_LIMIT,
    STOP_SIGNS,
    RED_LIGHTS,
    CROSSWALKS,
    SPEED_BUMPS,
    COMPLETES,  # `reach_s`; `completes: false` turns it off
    MINIMUM_RISK_STOP,
    STORY,
    # when the scenario sets their key
    MAX_DECEL,  # `max_decel`
    MIN_GAP,  # `min_gap`
    FOLLOWING_GAP,  # `following_gap`
    LANE_CHANGE,  # `lane_change`
    STANDSTILL_GAP,  # `standstill_gap`
    RESUME_WITHIN,  # `resume_within`
    MAX_JERK,  # `max_jerk`
    COMFORT,  # `comfort`
    MAX_WAIT_WITH_RIGHT_OF_WAY,  # `max_wait_with_right_of_way`
    NCAP,  # `ncap`
)


@dataclass(frozen=True, slots=True)
class CriteriaSettings:
    """A scenario's `criteria:` section, validated: the keys it sets, each with its value
    as its declaration's setting type gives it (a number in the unit the key's doc says, a
    tuple, a settings model). A key left out is absent: its criteria are off, or at their
    defaults for those that always apply. Made with `CriteriaSettings.of`."""

    items: tuple[tuple[str, object], ...] = ()  # (key, value), sorted by key

    @classmethod
    def of(cls, values: Mapping[str, object]) -> CriteriaSettings:
        """The settings of `values` (key -> value; a None value is a key left out)."""
        return cls(tuple(sorted((k, v) for k, v in values.items() if v is not None)))

    def get(self, key: str) -> object:
        """The value of `key`, None when the scenario leaves it out."""
        return next((v for k, v in self.items if k == key), None)

    def keys(self) -> tuple[str, ...]:
        """The keys set, sorted."""
        return tuple(k for k, _ in self.items)


def keyed() -> tuple[Declaration[Any], ...]:
    """The declarations a scenario's `criteria:` section can name, in registry order."""
    return tuple(d for d in DECLARATIONS if d.key is not None)


def switches() -> tuple[Declaration[Any], ...]:
    """The declarations of always-on criteria a scenario can turn off (`completes: false`),
    in registry order."""
    return tuple(d for d in DECLARATIONS if d.switch is not None)


def setting_keys() -> tuple[str, ...]:
    """Every key a scenario's `criteria:` section may set: the declarations' keys, then
    their switches."""
    return (tuple(str(d.key) for d in keyed())
            + tuple(str(d.switch) for d in switches()))


def build_criteria(settings: CriteriaSettings, run: RunInputs) -> CriteriaSet:
    """The run's criteria, in registry order, and what their samples must carry: the needs
    of their declarations, but not those of a criterion this run leaves idle."""
    unknown = set(settings.keys()) - set(setting_keys())
    if unknown:
        raise ValueError(f"no criteria declare the keys {sorted(unknown)}")
    items: list[Criterion] = []
    needs: set[Need] = set()
    for d in DECLARATIONS:
        if d.switch is not None and settings.get(d.switch) is False:
            continue
        setting = None if d.key is None else settings.get(d.key)
        if setting is None and not d.always:
            continue
        built = list(d.build(setting, run))
        items += built
        if not all(c.idle for c in built):
            needs |= d.needs | (d.needs_if_set if setting is not None else frozenset())
    return CriteriaSet(items, frozenset(needs))
