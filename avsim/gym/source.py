"""Where an episode's scenario comes from: one scenario file (or bundled name), or a campaign
family (an `avsim/1` file with `vary:`), from whose laws each episode draws a concrete
scenario by the campaign engine's sampling (`avsim.batch.sampling.draw_run`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from avsim.batch.campaign import Family, load_family
from avsim.batch.sampling import SEED_KEY, draw_run
from avsim.batch.suite import overrides_of
from avsim.scenario.files import read_raw
from avsim.scenario.load import load_scenario, scenario_path
from avsim.scenario.scenario import Scenario

MAX_EPISODE_SEED = 2**31 - 1  # an episode's seed is drawn in [0, this]


class ScenarioSource:
    """Makes each episode's scenario from `scenario` (a path or bundled name) with the
    user's `overrides` (dotted key paths, as `avsim run --set`). A fixed YAML scenario gets
    the episode's seed as its `seed` (its sensors' noise and any randomness of its actors);
    a family draws its `vary:` values and seed from it; an OpenSCENARIO file is played as it
    is (its runs are deterministic whatever the seed)."""

    def __init__(self, scenario: str | Path, overrides: Mapping[str, object] | None = None,
                 search_paths: tuple[Path, ...] = ()) -> None:
        self.name = str(scenario)
        self.overrides = dict(overrides or {})
        self.search_paths = search_paths
        path = scenario_path(self.name)
        self.yaml = path.suffix != ".xosc"
        self.family: Family | None = None
        if self.yaml and "vary" in read_raw(path):
            self.family = load_family(self.name, 0)

    def scenario(self, seed: int) -> Scenario:
        """The episode's scenario for `seed` (same seed, same scenario)."""
        overrides = dict(self.overrides)
        if self.family is not None:  # the user's overrides win over the drawn values
            overrides = overrides_of(draw_run(self.family.laws, seed, 0, 0)) | overrides
        elif self.yaml and SEED_KEY not in overrides:
            overrides[SEED_KEY] = seed
        return load_scenario(self.name, overrides, search_paths=self.search_paths)
