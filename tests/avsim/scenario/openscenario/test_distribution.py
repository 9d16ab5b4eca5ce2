"""ParameterValueDistribution files expanded into their concrete runs: the deterministic
ones equal esmini's permutations (order, count, values: `tests/data/esmini_ref`), the
stochastic ones are the same draws for the same file, and every bad or oversized file is
refused with the one-line error."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.distribution import is_distribution, load_distribution
from avsim.scenario.openscenario.distribution_values import MAX_RUNS
from avsim.scenario.openscenario.expressions import evaluate

DATA = Path(__file__).parents[3] / "data"
ORACLE = DATA / "esmini_ref" / "distributions.csv"
SEARCH = (DATA / "ncap",)  # the NCAP variations name their base scenario in ../
ASAM13 = DATA / "asam_examples/exampleFilesVersion1_3"
CCR = DATA / "ncap/OpenSCENARIO/NCAP/AEB_C2C_2023"
STOCHASTIC = ASAM13 / "SlowPrecedingVehicleStochasticParameterSet.xosc"


def _oracle() -> dict[str, tuple[int, dict[int, list[tuple[str, str]]]]]:
    """file -> (esmini's permutation count, permutation -> its parameters in order)."""
    found: dict[str, tuple[int, dict[int, list[tuple[str, str]]]]] = {}
    with ORACLE.open(newline="") as f:
        for row in csv.DictReader(f):
            params = [(n, v) for n, _, v in
                      (item.partition("=") for item in row["parameters"].split("; "))]
            entry = found.setdefault(row["file"], (int(row["n_permutations"]), {}))
            entry[1][int(row["permutation"])] = params
    return found


def _same_value(ours: str, esmini: str) -> bool:
    """Equal as numbers when both are numbers (esmini's log writes 30 for 30.000000), else
    equal as text; an expression is compared by its value (esmini's log lists the value).
    """
    if ours.startswith("${") and ours.endswith("}"):  # the scenario evaluates it
        value = evaluate(ours[2:-1], _no_parameters)
        assert isinstance(value, float)
        ours = repr(round(value, 6))  # the digits esmini's log writes
    try:
        return float(ours) == float(esmini)
    except ValueError:
        return ours == esmini


def _no_parameters(name: str) -> float:
    raise AssertionError(f"a distribution value references ${name}")


ORACLE_FILES = sorted(_oracle().items())


def test_the_oracle_covers_every_vendored_deterministic_file() -> None:
    vendored = {str(p.relative_to(DATA)) for p in DATA.glob("*/**/*.xosc") if is_distribution(p)}
    deterministic = {f for f in vendored if "Stochastic" not in f}
    assert len(ORACLE_FILES) == 50  # 47 NCAP, 3 ASAM
    assert deterministic == {f for f, _ in ORACLE_FILES}


@pytest.mark.parametrize(("file", "expected"), ORACLE_FILES, ids=[f for f, _ in ORACLE_FILES])
def test_deterministic_expansion_is_esminis(
        file: str, expected: tuple[int, dict[int, list[tuple[str, str]]]]) -> None:
    count, permutations = expected
    dist = load_distribution(DATA / file, SEARCH)
    assert not dist.stochastic
    assert len(dist.runs) == count
    for k, params in permutations.items():
        run = dist.runs[k]
        assert run.index == k
        ours, esmini = dict(run.parameters), dict(params)
        assert sorted(ours) == sorted(esmini)  # esmini's log lists them in its own order
        assert all(_same_value(ours[n], esmini[n]) for n in esmini), (k, run.label())


def test_the_scenario_file_resolves_beside_the_distribution() -> None:
    dist = load_distribution(CCR / "Variations/NCAP_AEB_C2C_CCRm_Variation_2023.xosc", SEARCH)
    assert dist.scenario == (CCR / "NCAP_AEB_C2C_CCR_2023.xosc").resolve()
    assert dist.runs[1].overrides() == {
        "parameters.Scenario_ID": "CCRm", "parameters.Ego_speed_kph": "30",
        "parameters.Overlap": "-75", "parameters.GVT_final_speed_kph": "20",
        "parameters.GVT_init_speed_kph": "20", "parameters.isCCRbraking": "false"}


def test_a_reference_out_of_the_folder_tree_needs_a_search_path() -> None:
    with pytest.raises(ScenarioError, match=r"ScenarioFile: filepath: .* is outside"):
        load_distribution(DATA / "ncap/OpenSCENARIO/NCAP/AEB_C2C_2023/Variations/"
                          "NCAP_AEB_C2C_CCRm_Variation_2023.xosc")


def test_stochastic_draws_are_the_files_own_and_repeat() -> None:
    first, again = load_distribution(STOCHASTIC), load_distribution(STOCHASTIC)
    assert first.stochastic and len(first.runs) == 100
    assert first.runs == again.runs
    speeds = [float(dict(r.parameters)["A1_Speed"]) for r in first.runs]
    assert all(15.0 <= s <= 30.0 for s in speeds)  # the Range truncates
    assert len(set(speeds)) == 100
    egos = {dict(r.parameters)["Ego_Speed"] for r in first.runs}
    assert egos <= {"10.0", "22.0", "25.0", "27.0", "28.0", "40.0", "60.0"}
    assert len(egos) >= 5  # weights 1..10 of 28 in 100 draws


HEAD = ('<?xml version="1.0"?><OpenSCENARIO><FileHeader revMajor="1" revMinor="{minor}"/>'
        '<ParameterValueDistribution><ScenarioFile filepath="base.xosc"/>{body}'
        '</ParameterValueDistribution></OpenSCENARIO>')


def _write(tmp_path: Path, body: str, minor: int = 2) -> Path:
    (tmp_path / "base.xosc").write_text("<OpenSCENARIO/>")
    path = tmp_path / "dist.xosc"
    path.write_text(HEAD.format(minor=minor, body=body))
    return path


def _single(name: str, inner: str) -> str:
    return (f'<DeterministicSingleParameterDistribution parameterName="{name}">{inner}'
            '</DeterministicSingleParameterDistribution>')


def _range(step: str, low: str, high: str) -> str:
    return (f'<DistributionRange stepWidth="{step}"><Range lowerLimit="{low}" '
            f'upperLimit="{high}"/></DistributionRange>')


@pytest.mark.parametrize("minor", [0, 1, 2, 3])
def test_ranges_include_their_end_and_the_last_axis_varies_fastest(tmp_path: Path,
                                                                   minor: int) -> None:
    body = ("<Deterministic>" + _single("a", _range("0.1", "0", "0.3"))
            + _single("b", '<DistributionSet><Element value="x"/><Element value="y"/>'
                           "</DistributionSet>") + "</Deterministic>")
    runs = load_distribution(_write(tmp_path, body, minor)).runs
    assert [r.label() for r in runs] == [
        "a=0, b=x", "a=0, b=y", "a=0.1, b=x", "a=0.1, b=y", "a=0.2, b=x", "a=0.2, b=y",
        "a=0.3, b=x", "a=0.3, b=y"]


def test_a_parameter_assigned_twice_takes_the_later_value(tmp_path: Path) -> None:
    body = ("<Deterministic>" + _single("a", '<DistributionSet><Element value="1"/>'
                                             "</DistributionSet>")
            + _single("a", '<DistributionSet><Element value="2"/></DistributionSet>')
            + "</Deterministic>")
    (run,) = load_distribution(_write(tmp_path, body)).runs
    assert run.parameters == (("a", "2"),)


def _stochastic(inner: str, runs: str = "3", seed: str = "7") -> str:
    return (f'<Stochastic numberOfTestRuns="{runs}" randomSeed="{seed}">'
            f'<StochasticDistribution parameterName="p">{inner}</StochasticDistribution>'
            "</Stochastic>")


@pytest.mark.parametrize("inner", [
    '<NormalDistribution expectedValue="5" variance="4"/>',
    '<LogNormalDistribution expectedValue="5" variance="4">'
    '<Range lowerLimit="1" upperLimit="9"/></LogNormalDistribution>',
    '<PoissonDistribution expectedValue="3"/>',
    '<UniformDistribution><Range lowerLimit="1" upperLimit="2"/></UniformDistribution>',
    '<Histogram><Bin weight="1"><Range lowerLimit="0" upperLimit="1"/></Bin>'
    '<Bin weight="3"><Range lowerLimit="5" upperLimit="6"/></Bin></Histogram>',
    '<ProbabilityDistributionSet><Element value="a" weight="1"/>'
    '<Element value="b" weight="0"/></ProbabilityDistributionSet>',
])
def test_every_stochastic_distribution_draws_the_same_runs_from_its_seed(
        tmp_path: Path, inner: str) -> None:
    path = _write(tmp_path, _stochastic(inner, runs="20"))
    first = load_distribution(path).runs
    assert len(first) == 20 and first == load_distribution(path).runs
    other = _write(tmp_path, _stochastic(inner, runs="20", seed="8"))
    values = [v for r in first for _, v in r.parameters]
    if "Element" not in inner:
        assert [v for r in load_distribution(other).runs for _, v in r.parameters] != values
    else:
        assert set(values) == {"a"}  # weight 0 is never drawn


@pytest.mark.parametrize(("body", "problem"), [
    ("<Deterministic>" + _single("a", _range("0", "0", "1")) + "</Deterministic>",
     "stepWidth must be > 0"),
    ("<Deterministic>" + _single("a", _range("1", "2", "1")) + "</Deterministic>",
     "upperLimit 1 is below lowerLimit 2"),
    ("<Deterministic>" + _single("a", _range("1e-9", "0", "1")) + "</Deterministic>",
     f"more than {MAX_RUNS} steps"),
    ("<Deterministic>" + _single("a", _range("1", "0", "40")) * 2 + "</Deterministic>",
     f"more than {MAX_RUNS} permutations"),
    ("<Deterministic>" + _single("a", "<UserDefinedDistribution/>") + "</Deterministic>",
     r"not supported yet \(UserDefinedDistribution\)"),
    ("<Deterministic>" + _single("a", "<DistributionSet/>") + "</Deterministic>",
     "no values"),
    ("<Deterministic/>", "no distribution"),
    ("", "expected one of Deterministic or Stochastic"),
    (_stochastic("<UserDefinedDistribution/>"), r"not supported yet \(UserDefinedDistribution\)"),
    (_stochastic('<NormalDistribution expectedValue="0" variance="1"/>', runs="1001"),
     f"numberOfTestRuns must be an integer from 1 to {MAX_RUNS}"),
    (_stochastic('<NormalDistribution expectedValue="0" variance="1"/>', seed="-1"),
     "randomSeed must be an integer"),
    (_stochastic('<NormalDistribution expectedValue="0" variance="-1"/>'),
     "variance must be >= 0"),
    (_stochastic('<NormalDistribution expectedValue="0" variance="1">'
                 '<Range lowerLimit="100" upperLimit="101"/></NormalDistribution>'),
     "no value inside the range in 10000 draws"),
    (_stochastic('<NormalDistribution expectedValue="nan" variance="1"/>'),
     "expectedValue: expected a finite number"),
])
def test_bad_distributions_are_refused_in_one_line(tmp_path: Path, body: str,
                                                   problem: str) -> None:
    with pytest.raises(ScenarioError, match=problem) as caught:
        load_distribution(_write(tmp_path, body))
    assert "\n" not in str(caught.value)
    assert str(caught.value).startswith(str(tmp_path / "dist.xosc"))


def test_a_missing_scenario_file_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, "<Deterministic>" + _single(
        "a", '<DistributionSet><Element value="1"/></DistributionSet>') + "</Deterministic>")
    (tmp_path / "base.xosc").unlink()
    with pytest.raises(ScenarioError, match="scenario file not found"):
        load_distribution(path)


def test_only_distribution_files_are_distributions(tmp_path: Path) -> None:
    assert is_distribution(STOCHASTIC)
    assert not is_distribution(ASAM13 / "SlowPrecedingVehicle.xosc")
    assert not is_distribution(tmp_path / "missing.xosc")
