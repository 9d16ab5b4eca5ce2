"""Tests of the `avsim` command line (`avsim.cli`) as a user runs it.

SCENARIO_FORMAT.md, "Command line": bad input exits 2 with one line on stderr naming the
file and the key, no traceback, and no output file; `list`, `schema`; the commands that come
later say so. No scenario is run here: every `run` below is rejected before the simulator
starts: PyBullet prints a "pybullet build time" banner when it is imported (on stderr, from
C), so bad input must leave stdout empty and stderr one line without that banner.

Every invocation of the module fixture runs in its own working directory. One of each kind
of refusal (YAML, model, OpenSCENARIO, output path, batch, usage) runs as a real process
(`REAL`: each costs an interpreter start and avsim's imports, ~1.6 s); the others run in
one process, one after another, through click's runner (`cli_driver.py`), which reports
whether each imported PyBullet (what the banner shows of a real process). Every bad fixture
file also goes through the command in this process.
"""

from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import jsonschema  # type: ignore[import-untyped]
import pytest
import yaml
from click.testing import CliRunner

from avsim.cli import main
from tests.avsim.scenario.test_load import BAD
from tests.avsim.texts import MINIMAL

HERE = Path(__file__).parent
BAD_DIR = HERE / "bad_scenarios"
REPO = HERE.parents[1]
SCENARIOS = REPO / "scenarios"
TIMEOUT = 60.0  # [s] per subprocess; a bad input that is not rejected would start a long run
EXIT_BAD_INPUT = 2



@dataclass(frozen=True)
class Case:
    """One `avsim` invocation: its arguments and what a bad input must name."""

    args: tuple[str, ...]
    file: str = ""  # the file (or name) the message must contain; "" for other commands
    key: str = ""  # the key the message must contain; "" when there is none


@dataclass(frozen=True)
class Outcome:
    cwd: Path  # the working directory it ran in (a `tmp/` directory was made there first)
    returncode: int
    stdout: str
    stderr: str
    pybullet: bool = False  # it imported PyBullet (in-process; a real process prints BANNER)


def _run_args(scenario: str) -> tuple[str, ...]:
    return ("run", scenario, "--out", "tmp/x.rrd", "--json", "tmp/x.json", "--no-progress")


# bad_scenarios/ fixtures that also go through the module fixture (a fresh interpreter that
# must not import PyBullet): one per kind of check (YAML, file shape, model validation,
# cross-key checks, unsupported features)
SUBPROCESS_FIXTURES = (
    "bad_yaml_syntax", "duplicate_key", "not_a_mapping", "unknown_nested_key", "wrong_type",
    "actor_lane_out_of_range", "after_forward", "town_route_leaves_town",
    "unknown_vehicle_model",
)


def _fixture_case(stem: str) -> Case:
    path = BAD_DIR / f"{stem}.yaml"
    return Case(_run_args(str(path)), str(path), BAD[stem][0])


def _inputs(directory: Path) -> dict[str, Case]:
    """Bad-input cases for subprocesses: a few fixtures plus inputs made here."""
    cases = {f"fixture_{stem}": _fixture_case(stem) for stem in SUBPROCESS_FIXTURES}
    missing = directory / "does_not_exist.yaml"
    cases["missing_file"] = Case(_run_args(str(missing)), str(missing), "(file)")
    cases["missing_bundled_name"] = Case(_run_args("no_such_scenario"), "no_such_scenario",
                                         "(file)")
    empty = directory / "empty_here.yaml"
    empty.write_text("", encoding="utf-8")
    cases["empty_file"] = Case(_run_args(str(empty)), str(empty), "(file)")
    comments = directory / "only_comments.yaml"
    comments.write_text("# nothing here\n\n", encoding="utf-8")
    cases["only_comments"] = Case(_run_args(str(comments)), str(comments), "(file)")
    unknown = directory / "unknown_key.yaml"
    unknown.write_text(MINIMAL.replace("set_speed_kph: 40}", "set_speed_kph: 40, colour: red}"),
                       encoding="utf-8")
    cases["unknown_key"] = Case(_run_args(str(unknown)), str(unknown), "ego.colour")
    cases["out_is_a_directory"] = Case(
        ("run", "normal_driving", "--out", "tmp", "--json", "tmp/x.json", "--no-progress"),
        "tmp", "--out")
    cases["run_set_two_values"] = Case(
        (*_run_args("normal_driving"), "--set", "actors.0.speed_kph=20,30"), "--set",
        "actors.0.speed_kph")
    cases["run_set_bad_path"] = Case((*_run_args("normal_driving"), "--set",
                                      "actors.7.speed_kph=20"), "normal_driving", "actors.7")
    cases["run_set_bad_value"] = Case((*_run_args("normal_driving"), "--set", "duration=-3"),
                                      "normal_driving", "duration")
    # a profile that cannot run the scenario honestly: no camera to read its lights
    cases["lights_without_a_camera"] = Case(
        (*_run_args("traffic_light"), "--profile", "none"), "traffic_light", "road.features")
    cases |= _openscenario_inputs(directory)
    a_file = directory / "a_file.txt"
    a_file.write_text("not a directory\n", encoding="utf-8")
    below_file = str(a_file / "sub" / "x.rrd")
    cases["out_below_a_file"] = Case(
        ("run", "normal_driving", "--out", below_file, "--json", "tmp/x.json", "--no-progress"),
        below_file, "--out")
    return cases


ALKS = HERE.parent / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"


def _openscenario_inputs(directory: Path) -> dict[str, Case]:
    """Bad OpenSCENARIO input: each names the file and where in it."""
    cases = {"xosc_param_breaks_a_constraint": Case(
        (*_run_args(str(CUT_IN)), "--param", "Ego_InitSpeed_Ve0_kph=70"), str(CUT_IN),
        "ParameterDeclaration[Ego_InitSpeed_Ve0_kph]")}
    text = CUT_IN.read_text(encoding="utf-8-sig").replace("./", f"{ALKS}/")
    bad = {
        "xosc_malformed": (text.replace("</Entities>", "</Entitie>"), "line"),
        "xosc_unresolved_reference": (text.replace('value="$CutInVehicle_Model"',
                                                   'value="$Nope"').replace(
            'entryName="$CutInVehicle_Model"', 'entryName="$Nope"'), "$Nope"),
        "xosc_unsupported_action": (text.replace(
            "<ActivateControllerAction lateral=\"true\" longitudinal=\"true\" />",
            '<VisibilityAction graphics="true" traffic="true" sensors="false"/>'),
            "not supported yet"),
        "xosc_missing_road": (text.replace("alks_road_straight.xodr", "no_road.xodr"),
                              "no_road.xodr"),
        "xosc_missing_catalog": (text.replace("catalogs/vehicles", "catalogs/no_vehicles"),
                                 "no_vehicles"),
    }
    for name, (content, key) in bad.items():
        path = directory / f"{name}.xosc"
        path.write_text(content, encoding="utf-8")
        cases[name] = Case((*_run_args(str(path)), "--search-path", str(ALKS)), str(path), key)
    junction = HERE.parent / "world" / "map" / "opendrive" / "data" / "junction.xodr"
    path = directory / "xosc_road_with_junction.xosc"
    path.write_text(text.replace(f"{ALKS}/road_networks/alks_road_straight.xodr",
                                 str(junction)), encoding="utf-8")
    cases["xosc_road_with_junction"] = Case(
        (*_run_args(str(path)), "--search-path", str(ALKS), "--search-path",
         str(junction.parent)), str(junction), "not supported yet (junctions)")
    return cases


def _launch(case: Case, cwd: Path) -> Outcome:
    proc = subprocess.run([sys.executable, "-m", "avsim.cli", *case.args], cwd=cwd,
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)
    return Outcome(cwd, proc.returncode, proc.stdout, proc.stderr)


def _in_one_process(cases: dict[str, Case], dirs: dict[str, Path]) -> dict[str, Outcome]:
    """`cases` run one after another in one process through click's runner (`cli_driver`)."""
    todo = [[name, list(case.args), str(dirs[name])] for name, case in cases.items()]
    proc = subprocess.run([sys.executable, str(HERE / "cli_driver.py")], input=json.dumps(todo),
                          capture_output=True, text=True, timeout=TIMEOUT * 4, check=False)
    assert proc.returncode == 0, proc.stderr
    return {name: Outcome(dirs[name], o["returncode"], o["stdout"], o["stderr"], o["pybullet"])
            for name, o in json.loads(proc.stdout).items()}


OTHER: dict[str, Case] = {
    "list": Case(("list",)),
    "schema": Case(("schema",)),
    # batches validate every run before any starts: one bad file or value, nothing runs
    "suite_bad_file": Case(("suite", str(SCENARIOS / "normal_driving.yaml"),
                            str(BAD_DIR / "unknown_top_key.yaml"), "--out", "tmp/suite")),
    "suite_empty_dir": Case(("suite", str(HERE), "--out", "tmp/suite")),
    "sweep_bad_value": Case(("sweep", "normal_driving", "--set", "actors.0.speed_kph=20,fast",
                             "--out", "tmp/sweep")),
    "sweep_bad_path": Case(("sweep", "normal_driving", "--set", "actors.7.speed_kph=20,30",
                            "--out", "tmp/sweep")),
    "sweep_no_equals": Case(("sweep", "normal_driving", "--set", "seed", "--out", "tmp/sweep")),
    "snapshot_missing": Case(("snapshot", "tmp/none.rrd", "--at", "3")),
    "bogus_profile": Case(("run", "--profile", "bogus", "normal_driving")),
}

BAD_CASE_NAMES = [f"fixture_{stem}" for stem in SUBPROCESS_FIXTURES] + [
    "missing_file", "missing_bundled_name", "empty_file", "only_comments", "unknown_key",
    "out_is_a_directory", "out_below_a_file", "run_set_two_values", "run_set_bad_path",
    "run_set_bad_value", "lights_without_a_camera", "xosc_param_breaks_a_constraint",
    "xosc_malformed", "xosc_unresolved_reference", "xosc_unsupported_action",
    "xosc_missing_road", "xosc_missing_catalog", "xosc_road_with_junction",
]


@pytest.fixture(scope="module")
def cases(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Case]:
    return {**_inputs(tmp_path_factory.mktemp("inputs")), **OTHER}


@pytest.fixture(scope="module")
def outcomes(cases: dict[str, Case], tmp_path_factory: pytest.TempPathFactory,
             ) -> dict[str, Outcome]:
    dirs = {name: tmp_path_factory.mktemp(f"cwd_{name}") for name in cases}
    for cwd in dirs.values():
        (cwd / "tmp").mkdir()
    with ThreadPoolExecutor(max_workers=len(REAL) + 1) as pool:
        real = {name: pool.submit(_launch, cases[name], dirs[name]) for name in REAL}
        rest = pool.submit(_in_one_process,
                           {name: case for name, case in cases.items() if name not in REAL},
                           dirs)
        return {**{name: future.result() for name, future in real.items()}, **rest.result()}


BANNER = "pybullet build time"  # printed by `import pybullet`
# the invocations that run as real processes: one of each kind of refusal (module doc)
REAL = ("fixture_bad_yaml_syntax", "fixture_after_forward", "missing_file",
        "xosc_unsupported_action", "out_below_a_file", "suite_bad_file", "bogus_profile")


def _assert_one_line_error(out: Outcome) -> str:
    assert "Traceback" not in out.stderr, out.stderr
    assert BANNER not in out.stderr + out.stdout and not out.pybullet, (
        "PyBullet was imported before the input check")
    assert out.stderr.endswith("\n") and out.stderr.count("\n") == 1, (
        f"stderr is not exactly one line: {out.stderr!r}"
    )
    line = out.stderr.strip()
    assert line
    return line


def test_every_bad_case_is_listed(cases: dict[str, Case]) -> None:
    assert set(BAD_CASE_NAMES) == set(cases) - set(OTHER)
    assert set(REAL) < set(cases)


@pytest.mark.parametrize("name", BAD_CASE_NAMES)
def test_bad_input_exits_2_with_one_line_and_writes_nothing(
    name: str, cases: dict[str, Case], outcomes: dict[str, Outcome]
) -> None:
    case, out = cases[name], outcomes[name]
    assert out.returncode == EXIT_BAD_INPUT, (out.returncode, out.stderr)
    line = _assert_one_line_error(out)
    assert case.file in line
    assert case.key in line
    assert out.stdout == ""
    assert not (out.cwd / "tmp" / "x.rrd").exists()
    assert not (out.cwd / "tmp" / "x.json").exists()
    assert list((out.cwd / "tmp").iterdir()) == [], "a partial file was left in tmp/"
    assert [p.name for p in out.cwd.iterdir()] == ["tmp"], "something was written (runs/?)"


@pytest.mark.parametrize("stem", sorted(p.stem for p in BAD_DIR.glob("*.yaml")))
def test_every_bad_fixture_is_rejected_in_process(
    stem: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    case = _fixture_case(stem)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tmp").mkdir()
    result = CliRunner().invoke(main, list(case.args))
    assert isinstance(result.exception, SystemExit), result.exception  # not a crash
    assert result.exit_code == EXIT_BAD_INPUT, (result.exit_code, result.stderr)
    line = _assert_one_line_error(Outcome(tmp_path, result.exit_code, result.stdout,
                                          result.stderr))
    assert case.file in line
    assert case.key in line
    assert result.stdout == ""
    assert [p.name for p in tmp_path.iterdir()] == ["tmp"]
    assert list((tmp_path / "tmp").iterdir()) == []


def _listed(stdout: str) -> dict[str, list[list[str]]]:
    """`avsim list`'s output: each folder heading's rows (name, situation, description)."""
    groups: dict[str, list[list[str]]] = {}
    heading = ""
    for line in stdout.splitlines():
        if "\t" in line:
            groups[heading].append(line.split("\t"))
        elif line:
            heading = line.split(" (")[0]
            groups[heading] = []
    return groups


def test_list_prints_every_bundled_scenario_by_folder(outcomes: dict[str, Outcome]) -> None:
    out = outcomes["list"]
    assert out.returncode == 0, out.stderr
    groups = _listed(out.stdout)
    alks = ALKS.relative_to(REPO).as_posix() + "/"
    assert list(groups) == ["scenarios/", "scenarios/acceptance/", "scenarios/faults/", alks]
    for heading, pattern, prefix in (("scenarios/", "*.yaml", ""),
                                     ("scenarios/acceptance/", "*.yaml", "acceptance/"),
                                     ("scenarios/faults/", "*.yaml", "faults/")):
        files = sorted((REPO / heading).glob(pattern))
        rows = groups[heading]
        assert len(rows) == len(files) > 0, heading
        assert [row[0] for row in rows] == [prefix + path.stem for path in files]
    assert len(groups[alks]) == len(list(ALKS.glob("alks_scenario_*.xosc"))) == 15
    rows = [row for group in groups.values() for row in group]
    assert all(len(row) == 3 for row in rows), rows  # name, situation, description
    assert all(row[1] != "(invalid)" for row in rows), rows
    names = {row[0] for row in rows}
    assert {"normal_driving", "acceptance/ncap_ccrs", "faults/lidar_outage",
            "alks/4_4_1_cut_in_no_collision"} <= names


def test_every_listed_name_resolves_to_its_file(outcomes: dict[str, Outcome]) -> None:
    from avsim.scenario.load import load_scenario, scenario_path

    for heading, rows in _listed(outcomes["list"].stdout).items():
        for name, _situation, description in rows:
            path = scenario_path(name)
            assert path.is_relative_to(REPO / heading), (name, path)
            assert load_scenario(name).description == description


def test_schema_is_a_json_schema_that_accepts_the_bundled_scenario(
    outcomes: dict[str, Outcome],
) -> None:
    out = outcomes["schema"]
    assert out.returncode == 0, out.stderr
    schema = json.loads(out.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    validator = jsonschema.Draft202012Validator(schema)
    scenario = yaml.safe_load((SCENARIOS / "normal_driving.yaml").read_text(encoding="utf-8"))
    validator.validate(scenario)
    # and it can say no: an unknown key is rejected by the schema too
    assert not validator.is_valid({**scenario, "colour": "red"})


@pytest.mark.parametrize(
    ("command", "names"),
    [
        ("suite_bad_file", ("unknown_top_key.yaml", "colour")),
        ("suite_empty_dir", ("no scenario files",)),
        ("sweep_bad_value", ("normal_driving", "actors.0.speed_kph", "fast")),
        ("sweep_bad_path", ("normal_driving", "actors.7")),
        ("sweep_no_equals", ("--set seed", "PATH=V1,V2")),
        ("snapshot_missing", ("none.rrd",)),
    ],
)
def test_batch_and_snapshot_bad_input(command: str, names: tuple[str, ...],
                                      outcomes: dict[str, Outcome]) -> None:
    out = outcomes[command]
    assert out.returncode == EXIT_BAD_INPUT, (out.returncode, out.stderr)
    line = _assert_one_line_error(out)
    for name in names:
        assert name in line, line
    assert out.stdout == ""
    assert list((out.cwd / "tmp").iterdir()) == []  # nothing written


def test_unknown_profile_is_a_usage_error(outcomes: dict[str, Outcome]) -> None:
    out = outcomes["bogus_profile"]
    assert out.returncode == EXIT_BAD_INPUT, (out.returncode, out.stderr)
    assert "Traceback" not in out.stderr and BANNER not in out.stderr and not out.pybullet
    assert "Usage:" in out.stderr
    assert "--profile" in out.stderr and "bogus" in out.stderr
    assert out.stdout == ""
    assert [p.name for p in out.cwd.iterdir()] == ["tmp"]


def strict_json(text: str) -> object:
    """`text` parsed as strict JSON: NaN and the infinities (Python's extension) refused."""
    def refuse(constant: str) -> object:
        raise ValueError(f"not strict JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


def test_run_set_overrides_a_key_and_the_result_is_strict_json(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "avsim.cli", "run", "normal_driving", "--profile", "none",
         "--set", "duration=2.5", "--set", "ego.set_speed_kph=30", "--out",
         str(tmp_path / "x.rrd"), "--no-progress"],
        cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 1, proc.stderr  # stopped at 2.5 s: not completed
    result = strict_json((tmp_path / "x.json").read_text(encoding="utf-8"))
    assert isinstance(result, dict) and result["sim_time"] == 2.5
    verdicts = {c["name"]: c["verdict"] for c in result["criteria"]}
    assert verdicts["completes"] == "fail" and verdicts["stop_signs"] == "not_applicable"
    assert all(c["value"] is None for c in result["criteria"]
               if c["verdict"] == "not_applicable")
    with pytest.raises(ValueError, match="not strict JSON"):
        strict_json('{"value": Infinity}')


def test_an_openscenario_file_runs_to_a_recording_a_result_and_a_plot(tmp_path: Path) -> None:
    """`avsim run FILE.xosc` writes what a YAML file's run writes: the recording (valid),
    the result JSON and the PNG."""
    proc = subprocess.run(
        [sys.executable, "-m", "avsim.cli", "run", str(CUT_IN), "--profile", "none",
         "--set", "duration=2.0", "--out", str(tmp_path / "cut_in.rrd"), "--plot",
         str(tmp_path / "cut_in.png"), "--no-progress"],
        cwd=tmp_path, capture_output=True, text=True, timeout=180, check=False)
    assert proc.returncode == 1, proc.stderr  # stopped at 2 s: its story did not finish
    result = strict_json((tmp_path / "cut_in.json").read_text(encoding="utf-8"))
    assert isinstance(result, dict) and result["sim_time"] == 2.0
    assert result["scenario"] == CUT_IN.stem
    assert {c["name"]: c["verdict"] for c in result["criteria"]}["story"] == "fail"
    assert (tmp_path / "cut_in.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    verify = subprocess.run([str(Path(sys.executable).parent / "rerun"), "rrd", "verify",
                             str(tmp_path / "cut_in.rrd")], capture_output=True, text=True,
                            timeout=120, check=False)
    assert verify.returncode == 0, verify.stderr


def test_view_opens_the_recording_in_the_rerun_viewer(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`avsim view RUN.rrd` starts the viewer that came with avsim on the file; `--web`
    the web viewer (the viewer itself is not started here: there is no display)."""
    calls: list[list[str]] = []
    monkeypatch.setattr(subprocess, "call", lambda command: calls.append(command) or 0)
    recording = tmp_path / "run.rrd"
    recording.write_bytes(b"")
    viewer = str(Path(sys.executable).parent / "rerun")
    for args, command in ((["view", str(recording)], [viewer, str(recording)]),
                          (["view", "--web", str(recording)],
                           [viewer, "--web-viewer", str(recording)])):
        result = CliRunner().invoke(main, args)
        assert result.exit_code == 0, result.output
        assert calls.pop() == command
    result = CliRunner().invoke(main, ["view", str(tmp_path / "none.rrd")])
    assert result.exit_code == 2
    missing = tmp_path / "none.rrd"
    assert result.output.strip() == f"avsim: error: {missing}: (file): no such recording"


@pytest.mark.parametrize(("sim", "duration", "wall", "text"), [
    (0.0, 60.0, 1.0, ""), (10.0, 60.0, 5.0, "RTF 2.00, 25 s to go"),
    (30.0, 30.0, 40.0, "RTF 0.75, 0 s to go"),
])
def test_the_progress_line_gives_the_pace(sim: float, duration: float, wall: float,
                                          text: str) -> None:
    from avsim.cli import pace

    assert pace(sim, duration, wall) == text


def test_a_bundled_name_that_is_also_a_file_here_is_refused(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "normal_driving").write_text(MINIMAL, encoding="utf-8")
    result = CliRunner().invoke(main, ["run", "normal_driving", "--out", "x.rrd"])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert result.stderr.startswith("avsim: error: normal_driving: (file): ambiguous: a file "
                                    "here and the bundled ")
    assert "./normal_driving" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["normal_driving"]


def test_two_bundled_files_of_one_name_are_refused(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from avsim.scenario import files

    for stem in ("alks_scenario_9_9_9_template", "alks_scenario_9_9_9"):
        (tmp_path / f"{stem}.xosc").write_text("<OpenSCENARIO/>", encoding="utf-8")
    monkeypatch.setattr(files, "ALKS_DIR", tmp_path)
    result = CliRunner().invoke(main, ["run", "alks/9_9_9", "--out", str(tmp_path / "x.rrd")])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    line = result.stderr.strip()
    assert line.startswith("avsim: error: alks/9_9_9: (file): ambiguous bundled name: "), line
    assert line.count(".xosc") == 2 and "\n" not in line


# ---- suite: --set, --param, --criteria, --dry-run (nothing is simulated) ----------------


def _suite(tmp_path: Path, *args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, ["suite", *args, "--out", str(tmp_path / "out"),
                                       "--dry-run", "--jobs", "1"])
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        result.exception)  # not a crash
    return result.exit_code, result.stdout, result.stderr


def test_suite_dry_run_prints_every_run_with_the_suite_options(tmp_path: Path) -> None:
    code, out, err = _suite(tmp_path, "normal_driving", str(CUT_IN), "--set", "duration=3",
                            "--param", "Ego_InitSpeed_Ve0_kph=50", "--criteria", "r157",
                            "--profile", "none")
    assert code == EXIT_BAD_INPUT  # normal_driving has no parameters
    assert "normal_driving" in err and "parameters.Ego_InitSpeed_Ve0_kph" in err
    code, out, err = _suite(tmp_path, "acceptance/r157_cut_out", str(CUT_IN), "--set",
                            "duration=3", "--criteria", "r157", "--profile", "none")
    assert code == 0, err
    lines = out.splitlines()
    assert len(lines) == 6 + 1  # the file's grid, and the ALKS file
    assert all(line.startswith("avsim run ") and "--set duration=3 " in line
               and "--profile none" in line for line in lines)
    assert ["--criteria r157" in line for line in lines] == [False] * 6 + [True]
    assert lines[0].startswith("avsim run acceptance/r157_cut_out --set duration=3 --set "
                               "actors.0.actions.0.trigger.ego_s=")
    assert not (tmp_path / "out").exists()  # nothing written


def test_suite_refuses_a_key_a_file_does_not_have_naming_the_file(tmp_path: Path) -> None:
    code, out, err = _suite(tmp_path, str(SCENARIOS / "normal_driving.yaml"), str(CUT_IN),
                            "--set", "actors.0.speed_kph=20")
    assert code == EXIT_BAD_INPUT and out == ""
    assert err.startswith(f"avsim: error: {CUT_IN}: actors.0.speed_kph: cannot set"), err
    assert err.count("\n") == 1
    code, out, err = _suite(tmp_path, "traffic_jam", "--set", "actors.0.speed_kph=20,30")
    assert code == EXIT_BAD_INPUT and "suite takes one value" in err
    code, out, err = _suite(tmp_path, "acceptance/r157_cut_out", "--set",
                            "actors.0.actions.0.lane_change.lateral_speed=2")
    assert code == EXIT_BAD_INPUT
    assert "actors.0.actions.0.lane_change.lateral_speed: the file's grid sweeps" in err
    assert not (tmp_path / "out").exists()


def test_suite_criteria_reach_the_openscenario_runs(tmp_path: Path) -> None:
    from avsim.batch.jobs import Status, run_job
    from avsim.batch.suite import plan, suite_entries

    sidecar = tmp_path / "bad.criteria.yaml"
    sidecar.write_text("duration: -1\n", encoding="utf-8")
    code, _, err = _suite(tmp_path, "traffic_jam", str(CUT_IN), "--criteria", str(sidecar))
    assert code == EXIT_BAD_INPUT and f"{sidecar}: duration" in err, err
    good = tmp_path / "good.criteria.yaml"
    good.write_text("duration: 2\n", encoding="utf-8")
    jobs = plan(suite_entries(["traffic_jam", str(CUT_IN)]), tmp_path, "none", good)
    assert [job.criteria for job in jobs] == [None, good]
    good.write_text("duration: -1\n", encoding="utf-8")  # the worker loads it again
    outcome = run_job(jobs[1])
    assert outcome.status is Status.BAD_INPUT and f"{good}: duration" in (outcome.error or "")
