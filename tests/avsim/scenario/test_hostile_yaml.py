"""Hostile YAML inputs: files that are not regular, nesting, anchor and merge-key bombs, huge
integers, long names and `--set` grids. Each is refused with the one-line error (exit 2 and
nothing written through the CLI), and the work done before the refusal is bounded (the text
is never composed, no grid point is made)."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

from avsim.batch import sweep
from avsim.batch.sweep import Axis, SweepError, grid, parse_set
from avsim.cli import main
from avsim.scenario.bounds import MAX_DEPTH, MAX_INT_DIGITS, MAX_NAME_LENGTH, MAX_VALUES
from avsim.scenario.errors import LocatedError
from avsim.scenario.files import bundled_scenarios, parse_value, read_raw
from avsim.scenario.load import ScenarioError, load_scenario
from avsim.scenario.model import MAX_GRID_POINTS
from avsim.scenario.yaml_events import YamlBoundError, check_events

MINIMAL = """\
format: avsim/1
name: hostile
duration: 10
road: {lanes: 2, speed_limit_kph: 50, segments: [{straight: 200}]}
ego: {s: 20, set_speed_kph: 40}
"""
ALKS = (Path(__file__).parents[2] / "data" / "alks" / "logical_scenarios"
        / "concrete_scenarios" / "alks_scenario_4_6_2_lateral_detection_range_template.xosc")
HUGE = "1" + "0" * 4999  # an integer of 5000 digits: past Python's 4300-digit conversion


def _write(folder: Path, text: str, name: str = "s.yaml") -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def _error(path: Path | str, **kwargs: object) -> str:
    with pytest.raises(ScenarioError) as info:
        load_scenario(path, **kwargs)  # type: ignore[arg-type]
    message = str(info.value)
    assert "\n" not in message
    return message


@pytest.fixture
def never_composed(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Fail the test if PyYAML composes a document (the refusal must come before)."""
    def compose(*_: object, **__: object) -> None:
        raise AssertionError("the text was composed")

    monkeypatch.setattr(yaml, "load", compose)
    yield


# -- 1. files that are not regular --------------------------------------------------------


@pytest.mark.parametrize("kind", ["device", "symlink", "fifo", "directory"])
def test_a_file_that_is_not_regular_is_refused_unread(kind: str, tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    if kind == "device":
        path = Path("/dev/zero")
    elif kind == "symlink":
        path.symlink_to("/dev/zero")
    elif kind == "fifo":
        os.mkfifo(path)  # no writer: a blocking open or read would wait forever
    else:
        path.mkdir()
    word = {"device": "a character device", "symlink": "a character device",
            "fifo": "a FIFO", "directory": "a directory"}[kind]
    assert _error(path) == f"{path}: (file): not a regular file ({word})"


def test_a_sidecar_that_is_not_regular_is_refused_unread() -> None:
    message = _error(ALKS, criteria_file=Path("/dev/zero"))
    assert message == "/dev/zero: (file): not a regular file (a character device)"


def test_read_raw_reads_at_most_the_bound(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL + "# " + "x" * 600_000 + "\n")
    with pytest.raises(LocatedError) as info:
        read_raw(path)
    assert (info.value.key, info.value.problem) == ("(file)", "over 524288 bytes: at most 524288")


@pytest.mark.parametrize("char", ["\x00", "\x01", "\ufffe"])
def test_a_character_yaml_does_not_allow_is_one_line_at_its_line(
    char: str, tmp_path: Path
) -> None:
    path = _write(tmp_path, MINIMAL + f"description: a{char}b\n")
    assert _error(path) == (
        f"{path}: line 6: YAML does not allow the character #x{ord(char):04x}")


# -- 2. nesting depth ---------------------------------------------------------------------


def _nested(depth: int) -> str:
    return "[" * depth + "]" * depth


@pytest.mark.parametrize("depth", [50_000, 1_000_000])
def test_the_event_walk_survives_any_depth(depth: int) -> None:
    with pytest.raises(YamlBoundError, match=f"nested deeper than {MAX_DEPTH} levels"):
        check_events(_nested(depth))


def test_the_deepest_nesting_allowed_loads_as_yaml() -> None:
    check_events(_nested(MAX_DEPTH))
    assert parse_value(_nested(MAX_DEPTH)) is not None
    with pytest.raises(YamlBoundError):
        parse_value(_nested(MAX_DEPTH + 1))


@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 500, 50_000])
def test_a_deeply_nested_file_is_refused_before_composing(
    depth: int, tmp_path: Path, never_composed: None
) -> None:
    path = _write(tmp_path, MINIMAL + "extra: " + _nested(depth) + "\n")
    assert _error(path) == (
        f"{path}: line 6: nested deeper than {MAX_DEPTH} levels (anchors expanded)")


def test_block_nesting_counts_too(tmp_path: Path, never_composed: None) -> None:
    text = MINIMAL + "".join(f"{'  ' * k}k{k}:\n" for k in range(MAX_DEPTH + 1)) + "  " * 66 + "1"
    assert f"nested deeper than {MAX_DEPTH} levels" in _error(_write(tmp_path, text))


def test_an_alias_counts_its_anchors_levels_where_it_is_used() -> None:
    half = MAX_DEPTH // 2 + 1
    text = f"a: &a {_nested(half)}\nb: {'[' * half}*a{']' * half}\n"
    with pytest.raises(YamlBoundError, match="line 2: nested deeper"):
        check_events(text)


def test_a_recursive_alias_is_refused() -> None:
    with pytest.raises(YamlBoundError, match=r"alias \*a inside its own anchor's node"):
        check_events("a: &a [1, *a]\n")


def test_overrides_of_the_deepest_values_allowed_copy(tmp_path: Path) -> None:
    """The loader's copy of the data (`apply_overrides`) and validation keep to the bound:
    the deepest value allowed, set by an override, gives the usual one-line error."""
    path = _write(tmp_path, MINIMAL)
    message = _error(path, overrides={"extra": parse_value(_nested(MAX_DEPTH))})
    assert message == f"{path}: extra: unknown key (set by an override)"


# -- 3. values counted while parsing, merge keys included --------------------------------


def _merge_bomb(levels: int, width: int = 10) -> str:
    """Each level's mapping merges the previous one `width` times (a `<<` list)."""
    lines = ["m0: &m0 {a: 1, b: 2, c: 3, d: 4, e: 5, f: 6, g: 7, h: 8, i: 9, j: 10}"]
    for k in range(1, levels):
        lines.append(f"m{k}: &m{k} {{<<: [{', '.join([f'*m{k - 1}'] * width)}]}}")
    return MINIMAL + "\n".join(lines) + "\n"


def test_a_merge_key_bomb_is_refused_before_composing(
    tmp_path: Path, never_composed: None
) -> None:
    path = _write(tmp_path, _merge_bomb(12))
    message = _error(path)
    assert message.endswith(f": more than {MAX_VALUES} values (anchors expanded)"), message
    assert message.startswith(f"{path}: line ")


def test_a_merge_key_counts_its_anchor_in_full() -> None:
    anchor = "{" + ", ".join(f"k{k}: {k}" for k in range(1000)) + "}"
    uses = "\n".join(f"u{k}: {{<<: *a}}" for k in range(MAX_VALUES // 2001 + 1))
    with pytest.raises(YamlBoundError, match="more than"):
        check_events(f"a: &a {anchor}\n{uses}\n")
    check_events(f"a: &a {anchor}\nu: {{<<: *a}}\n")


def test_merge_keys_and_duplicate_keys_read_as_before(tmp_path: Path) -> None:
    doc = read_raw(_write(tmp_path, "a: &a {x: 1, y: 2}\nb: {<<: *a, y: 3}\n"))
    assert doc == {"a": {"x": 1, "y": 2}, "b": {"x": 1, "y": 3}}
    with pytest.raises(LocatedError) as info:
        read_raw(_write(tmp_path, "x: 1\nx: 2\n"))
    assert (info.value.key, info.value.problem) == ("line 2", "duplicate key 'x' (first at line 1)")


def test_the_count_includes_every_key_and_value() -> None:
    flat = "{" + ", ".join(f"k{k}: {k}" for k in range(MAX_VALUES // 2)) + "}"
    with pytest.raises(YamlBoundError, match="more than"):
        check_events(flat)  # the mapping, its keys and its values: one over the bound
    check_events("[" + ", ".join(["1"] * (MAX_VALUES - 1)) + "]")


# -- 4. huge integers ---------------------------------------------------------------------


def test_a_huge_integer_in_a_file_is_refused_at_its_line(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL + f"seed: {HUGE}\n")
    assert _error(path) == (
        f"{path}: line 6: an integer of 5000 digits: at most {MAX_INT_DIGITS}")


@pytest.mark.parametrize("text", [HUGE, f"-{HUGE}", f"0x{'f' * 5000}", f"0o{'7' * 5000}",
                                  "9" * (MAX_INT_DIGITS + 1), f"[1, {{a: {HUGE}}}]"])
def test_a_huge_integer_value_is_refused(text: str) -> None:
    with pytest.raises(YamlBoundError, match=f"digits: at most {MAX_INT_DIGITS}"):
        parse_value(text)


def test_the_longest_integer_allowed_reads() -> None:
    assert parse_value("9" * MAX_INT_DIGITS) == int("9" * MAX_INT_DIGITS)
    assert parse_value(f"{HUGE}.5") > 0  # a float of any length is a float


def test_a_huge_integer_in_a_set_names_the_set() -> None:
    with pytest.raises(SweepError, match=r"^--set seed=1000.*\.\.\.: an integer of 5000 "):
        parse_set(f"seed={HUGE}")


def _refused(args: list[str], folder: Path) -> str:
    """Run the CLI in `folder`; assert exit 2, one line on stderr and nothing written."""
    before = set(folder.rglob("*"))
    runner = CliRunner()
    cwd = Path.cwd()
    os.chdir(folder)
    try:
        result = runner.invoke(main, args)
    finally:
        os.chdir(cwd)
    assert isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 2, (result.exit_code, result.output)
    assert set(folder.rglob("*")) == before
    lines = result.stderr.strip().splitlines()
    assert len(lines[-1]) < 400, lines[-1][:400]
    return lines[-1]


@pytest.mark.parametrize("args", [
    ["run", "normal_driving", "--seed", HUGE],
    ["run", "normal_driving", "--seed", "-1"],
    ["run", "normal_driving", "--seed", str(2**32)],
    ["run", "normal_driving", "--set", f"seed={HUGE}"],
    ["run", "normal_driving", "--set", f"actors.0.speed_kph={HUGE}"],
    ["sweep", "normal_driving", "--set", f"seed={HUGE}"],
    ["sweep", "normal_driving", "--set", f"actors.0.speed_kph=10,{HUGE}"],
])
def test_a_huge_number_on_the_command_line_is_refused(args: list[str], tmp_path: Path) -> None:
    line = _refused([*args, "--profile", "none"], tmp_path)
    assert line.startswith(("avsim: error: --set", "Error: Invalid value for '--seed'")), line


def test_a_huge_integer_in_a_suites_file_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL + f"seed: {HUGE}\n")
    line = _refused(["suite", str(path), "--profile", "none"], tmp_path)
    assert line == f"avsim: error: {path}: line 6: an integer of 5000 digits: at most 20"


# -- 5. names -----------------------------------------------------------------------------


def test_a_long_name_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL.replace("hostile", "n" * 300_000))
    assert _error(path) == (
        f"{path}: name: string should have at most {MAX_NAME_LENGTH} characters")
    longest = _write(tmp_path, MINIMAL.replace("hostile", "n" * MAX_NAME_LENGTH))
    assert load_scenario(longest).name == "n" * MAX_NAME_LENGTH


@pytest.mark.parametrize("name", ["../up", "a/b", ".hidden", "with space", "Ünï"])
def test_a_name_is_a_file_names_characters(name: str, tmp_path: Path) -> None:
    path = _write(tmp_path, MINIMAL.replace("hostile", f"'{name}'"))
    assert f"{path}: name: must match" in _error(path)


def test_the_bundled_names_and_the_grids_run_names_fit() -> None:
    names = [load_scenario(path).name for path in bundled_scenarios()]
    assert all(len(name) <= MAX_NAME_LENGTH for name in names)
    run_file = f".{'n' * MAX_NAME_LENGTH}_{MAX_GRID_POINTS - 1:03d}.rrd.partial"
    assert len(run_file.encode()) <= 255  # NAME_MAX of the usual file systems


# -- 6. sweep grids -----------------------------------------------------------------------


def test_a_set_of_too_many_values_is_refused_before_reading_them(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    read: list[str] = []
    monkeypatch.setattr(sweep, "parse_value", read.append)
    values = ",".join(str(k) for k in range(MAX_GRID_POINTS + 1))
    with pytest.raises(SweepError, match=f"1001 values: at most {MAX_GRID_POINTS}$"):
        parse_set(f"seed={values}")
    assert read == []


def test_a_grid_over_the_bound_is_refused_before_a_point_is_made() -> None:
    axes = [Axis(f"k{k}", tuple(range(1000))) for k in range(6)]  # 10^18 points
    with pytest.raises(SweepError, match=f"a grid of {10**18} points: at most 1000$"):
        grid(axes)
    assert len(grid([Axis("a", tuple(range(10))), Axis("b", tuple(range(100)))])) == 1000


def test_a_sweep_over_the_bound_is_refused(tmp_path: Path) -> None:
    values = ",".join(str(k) for k in range(101))
    line = _refused(["sweep", "normal_driving", "--set", f"seed={values}",
                     "--set", "ego.set_speed_kph=10,20,30,40,50,60,70,80,90,100"], tmp_path)
    assert line == "avsim: error: --set: a grid of 1010 points: at most 1000"
