"""A fuzzed YAML loader at the text level: Hypothesis mutates the bundled files' bytes
(inserted, deleted and replaced, invalid UTF-8 included) and writes hostile YAML of its own
(deep nesting in flow and block style, anchors and aliases, merge keys, recursive aliases,
huge integers and strings, several documents). Loading gives a scenario or the one-line
`ScenarioError`, never another exception (`test_fuzz.py` mutates the files key by key).
`--set` texts (`avsim.batch.sweep.parse_set`) give an axis or a `SweepError`.

What the worst of these cost is `bench/bench_load.py`'s (the deepest nesting allowed, the
largest merge bomb refused), not asserted here.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from avsim.batch.sweep import Axis, SweepError, parse_set
from avsim.scenario.bounds import MAX_DEPTH
from avsim.scenario.files import SCENARIO_DIR
from avsim.scenario.load import ScenarioError, load_scenario
from tests.fuzzing import FUZZ

pytestmark = pytest.mark.fuzz

FILES = sorted([*SCENARIO_DIR.glob("*.yaml"), *(SCENARIO_DIR / "acceptance").glob("*.yaml")])
TEXTS = {file: file.read_bytes() for file in FILES}
MINIMAL = """\
format: avsim/1
name: fuzz
duration: 10
road: {lanes: 2, speed_limit_kph: 50, segments: [{straight: 200}]}
ego: {s: 20, set_speed_kph: 40}
"""
BLOCK_DEPTH = 700  # levels of block-style nesting at most: about the file bound's 512 KiB
YAML_BYTES = st.sampled_from([b"[", b"]", b"{", b"}", b":", b"-", b"&a ", b"*a", b"<<: ",
                              b"\n", b"  ", b"'", b'"', b"#", b"!!", b"---\n", b"\xff",
                              b"\xc3", b"9" * 30, b"\t", b",", b"?", b"|", b">"])


def load_or_one_line_error(text: bytes) -> None:
    """Load `text` from a file: a scenario or a one-line `ScenarioError` naming the file."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.yaml"
        path.write_bytes(text)
        try:
            load_scenario(path)
        except ScenarioError as exc:
            message = str(exc)
            assert "\n" not in message, message
            assert message.startswith(f"{path}: "), message


@st.composite
def byte_mutations(draw: st.DrawFn) -> bytes:
    """A bundled file with a few bytes inserted, deleted or replaced."""
    text = bytearray(TEXTS[draw(st.sampled_from(FILES))])
    for _ in range(draw(st.integers(1, 8))):
        at = draw(st.integers(0, len(text)))
        how = draw(st.sampled_from(["insert", "delete", "replace"]))
        piece = draw(st.one_of(YAML_BYTES, st.binary(min_size=1, max_size=4)))
        if how == "insert":
            text[at:at] = piece
        elif how == "delete":
            del text[at:at + draw(st.integers(1, 40))]
        else:
            text[at:at + len(piece)] = piece
    return bytes(text)


def _nested(depth: int, flow: bool, leaf: str) -> str:
    if flow:
        return "[" * depth + leaf + "]" * depth
    depth = min(depth, BLOCK_DEPTH)  # block style grows as the square of its depth
    return "".join(f"\n{'  ' * (k + 1)}k{k}:" for k in range(depth)) + f" {leaf}"


@st.composite
def hostile_yaml(draw: st.DrawFn) -> bytes:
    """Hostile YAML after the minimal file: nesting around the depth bound and far past it,
    anchor and merge-key bombs, recursive aliases, huge scalars."""
    kind = draw(st.sampled_from(["nest", "bomb", "merge", "recursive", "scalar", "key"]))
    width = draw(st.integers(1, 12))
    levels = draw(st.integers(1, 8))
    if kind == "nest":
        depth = draw(st.one_of(st.integers(0, 2 * MAX_DEPTH), st.integers(1000, 60_000)))
        extra = _nested(depth, draw(st.booleans()), draw(st.sampled_from(["1", "*x", "~"])))
    elif kind in ("bomb", "merge"):
        lines = ["a0: &a0 {" + ", ".join(f"k{k}: {k}" for k in range(width)) + "}"]
        for k in range(1, levels):
            uses = ", ".join([f"*a{k - 1}"] * width)
            lines.append(f"a{k}: &a{k} " + (f"{{<<: [{uses}]}}" if kind == "merge"
                                           else f"[{uses}]"))
        extra = "\n" + "\n".join("  " + line for line in lines)
    elif kind == "recursive":
        extra = draw(st.sampled_from(["&r [*r]", "&r {a: *r}", "&r {<<: *r}", "*undefined"]))
    elif kind == "scalar":
        extra = draw(st.sampled_from(["9", "-9", "0x", "0o", "1.", "'x"])) * draw(
            st.integers(1, 20_000))
    else:
        extra = "{" + draw(st.sampled_from(["9" * 5000, "[1]", "{a: 1}", "*a", "<<"])) + ": 1}"
    field = draw(st.sampled_from(["extra", "seed", "name", "duration"]))
    text = MINIMAL.replace(f"{field}:", "was:") if field != "extra" else MINIMAL
    return (text + f"{field}: {extra}\n").encode()


@FUZZ
@given(byte_mutations())
def test_a_byte_mutated_file_loads_or_gets_its_one_line_error(text: bytes) -> None:
    load_or_one_line_error(text)


@FUZZ
@given(hostile_yaml())
def test_hostile_yaml_loads_or_gets_its_one_line_error(text: bytes) -> None:
    load_or_one_line_error(text)


SET_PARTS = st.one_of(st.text(max_size=30), st.sampled_from(
    ["seed=", "actors.0.speed_kph=", "parameters.X=", "[", "]", "{", "}", ",", "&a ", "*a",
     "<<: ", "9" * 30, "'", "\n", "!!python/object:os.system", "a.b..c=", "=1"]))


@FUZZ
@given(st.lists(SET_PARTS, max_size=12).map("".join))
def test_a_set_text_is_an_axis_or_a_sweep_error(text: str) -> None:
    try:
        axis = parse_set(text)
    except SweepError as exc:
        assert "\n" not in str(exc).strip() or "\n" in text
        return
    assert isinstance(axis, Axis) and axis.values


@FUZZ
@given(st.integers(1, 60_000), st.sampled_from(["[", "{a: ", "- "]))
def test_a_deep_set_value_is_a_sweep_error(depth: int, opening: str) -> None:
    closing = {"[": "]", "{a: ": "}", "- ": ""}[opening]
    text = "x=" + opening * depth + "1" + closing * depth
    if depth < MAX_DEPTH:
        assert parse_set(text).path == "x"
    else:
        with pytest.raises(SweepError, match="nested deeper than"):
            parse_set(text)
