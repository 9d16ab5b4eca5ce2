"""The campaign families of `scenarios/campaigns/`: each file loads as a campaign, its 20
first draws load and check as runs (`avsim campaign FILE --n 20 --dry-run`), every law's
whole range (a number's least and most value, each value of a choice) is a scenario the
format takes, and the file's own values (its nominal case) lie inside its laws. Nothing
runs: the files are only loaded and validated."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.batch.campaign import MISSING, Family, Settings, draw_plan, load_family
from avsim.batch.sampling import Law
from avsim.batch.suite import overrides_of
from avsim.scenario.load import load_scenario

REPO = Path(__file__).resolve().parents[3]
FAMILIES = sorted((REPO / "scenarios" / "campaigns").glob("*.yaml"))
DRAWS = 20  # runs drawn per family, as `--n 20`
SEED = 1  # the campaign's `--seed`
LEAST_FAMILIES = 12  # the situations the families cover (docs/cli.md "Campaigns")


def test_the_families_are_there() -> None:
    assert len(FAMILIES) >= LEAST_FAMILIES
    names = [load_family(str(f), 0).name for f in FAMILIES]
    assert names == [f.stem for f in FAMILIES]  # a family's runs are named by its file


@pytest.mark.parametrize("path", FAMILIES, ids=lambda p: p.stem)
def test_a_family_loads_and_its_first_draws_validate(path: Path, tmp_path: Path) -> None:
    family = load_family(str(path), 0)
    jobs, drawn = draw_plan([family], DRAWS, Settings(tmp_path, "fast", {}, seed=SEED))
    assert [j.name for j in jobs] == [f"{family.name}_{k:04d}" for k in range(DRAWS)]
    assert all(set(values) == {"seed", *(law.key for law in family.laws)}
               for values in drawn)
    assert not list(tmp_path.iterdir())  # checked, nothing written


def _ends(law: Law) -> list[object]:
    """The values that bound a law: a number's least and most, every value of a choice."""
    if law.kind == "integers":
        return [int(law.low), int(law.high)]
    if law.numeric:
        return [law.low, law.high]
    return list(law.values)


@pytest.mark.parametrize("path", FAMILIES, ids=lambda p: p.stem)
def test_every_law_stays_within_the_format(path: Path) -> None:
    """Each law's extreme values, one key at a time (the others at the nominal), load."""
    family = load_family(str(path), 0)
    for law in family.laws:
        for value in _ends(law):
            load_scenario(str(path), overrides_of({law.key: value}))


def _inside(law: Law, nominal: object) -> bool:
    if law.numeric:
        assert isinstance(nominal, int | float)
        return law.low <= nominal <= law.high
    return nominal in law.values


@pytest.mark.parametrize("path", FAMILIES, ids=lambda p: p.stem)
def test_the_nominal_case_lies_inside_its_laws(path: Path) -> None:
    """The file's own value of each varied key (where it writes one: else the format's
    default) is a value its law draws, so that shrinking moves toward a case of the family."""
    family: Family = load_family(str(path), 0)
    for law in family.laws:
        nominal = family.nominal(law.key)
        if nominal is not MISSING:
            assert _inside(law, nominal), f"{path.name}: {law.key}: nominal {nominal!r}"
