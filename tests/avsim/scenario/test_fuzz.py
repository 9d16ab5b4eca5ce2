"""A fuzzed loader (issue L 4): Hypothesis mutates the bundled scenario files key by key
(wrong types, out-of-range values, removed, duplicated and huge entries), and the ALKS
OpenSCENARIO files and their OpenDRIVE road element by element and attribute by attribute.

For every mutation, loading either gives a scenario (the run would go on: exit 0 or 1) or
the one-line `ScenarioError` (exit 2, nothing written: the CLI writes only after a file
loads), never another exception (a traceback). The examples are derandomized: the same
mutations on every machine and every run. How long the worst of them takes (a file grown to
its loader's bounds) is a benchmark, `bench/bench_load.py`, not asserted here: the machines
are shared and noisy (CI once took 6.6 s for a load of 1.4 s here).
"""

from __future__ import annotations

import copy
import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from avsim.scenario.files import SCENARIO_DIR, read_raw
from avsim.scenario.load import ScenarioError, load_scenario
from tests.fuzzing import FUZZ

FILES = sorted([*SCENARIO_DIR.glob("*.yaml"), *(SCENARIO_DIR / "acceptance").glob("*.yaml")])
ALKS = (Path(__file__).parents[2] / "data" / "alks" / "logical_scenarios"
        / "concrete_scenarios")
XOSC = sorted(ALKS.glob("alks_scenario_*.xosc"))

pytestmark = pytest.mark.fuzz

Path_ = tuple[str | int, ...]  # keys and list indices from the document's root


def paths(node: Any, prefix: Path_ = ()) -> Iterator[Path_]:
    """Every key path in a YAML document, parents before children."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*prefix, key)
            yield from paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield (*prefix, index)
            yield from paths(value, (*prefix, index))


def parent_of(doc: Any, path: Path_) -> Any:
    node = doc
    for part in path[:-1]:
        node = node[part]
    return node


VALUES = st.one_of(  # wrong types and out-of-range values
    st.none(), st.booleans(), st.integers(min_value=-(10**12), max_value=10**12),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=20),
    st.sampled_from([[], {}, [1, 2], {"x": 1}, -1, 0, 1e300, -1e-300, "1e9", ".5", "yes"]),
)


def mutate(doc: Any, path: Path_, how: str, value: Any) -> Any:
    """`doc` with the entry at `path` changed: set to `value`, removed, duplicated (a list
    item twice), or made huge (a long list of it, a long string, a huge number)."""
    doc = copy.deepcopy(doc)
    parent, last = parent_of(doc, path), path[-1]
    old = parent[last]
    if how == "set":
        parent[last] = value
    elif how == "remove":
        del parent[last]
    elif how == "duplicate" and isinstance(parent, list):
        parent.insert(int(last), copy.deepcopy(old))
    elif how == "huge":
        parent[last] = ([copy.deepcopy(old[0])] * 100_000 if isinstance(old, list) and old
                        else "x" * 1_000_000 if isinstance(old, str)
                        else 1e300 if isinstance(old, int | float) else [old] * 100_000)
    return doc


def load_or_one_line_error(path: Path, *named: Path) -> None:
    """Load `path`: a scenario or a one-line `ScenarioError` naming `path` or one of the
    files it refers to (`named`)."""
    try:
        load_scenario(path)
    except ScenarioError as exc:
        message = str(exc)
        assert "\n" not in message, message
        assert message.startswith(tuple(str(p) for p in (path, *named))), message


@st.composite
def yaml_mutations(draw: st.DrawFn) -> tuple[Path, Any]:
    file = draw(st.sampled_from(FILES))
    doc = read_raw(file)
    path = draw(st.sampled_from(list(paths(doc))))
    how = draw(st.sampled_from(["set", "set", "remove", "duplicate", "huge"]))
    return file, mutate(doc, path, how, draw(VALUES))


@FUZZ
@given(yaml_mutations())
def test_a_mutated_scenario_file_loads_or_gets_its_one_line_error(
        mutation: tuple[Path, Any]) -> None:
    file, doc = mutation
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / file.name
        text = yaml.safe_dump(doc, sort_keys=False, allow_unicode=True, width=1_000_000)
        path.write_text(text, encoding="utf-8")
        load_or_one_line_error(path)


def test_the_mutations_reach_every_file_and_kind() -> None:
    """The strategy can draw from every bundled file, and each kind changes the document."""
    doc = {"a": [1, 2], "b": {"c": "x"}}
    assert list(paths(doc)) == [("a",), ("a", 0), ("a", 1), ("b",), ("b", "c")]
    assert mutate(doc, ("a", 0), "remove", None) == {"a": [2], "b": {"c": "x"}}
    assert mutate(doc, ("a", 1), "duplicate", None)["a"] == [1, 2, 2]
    assert len(mutate(doc, ("b", "c"), "huge", None)["b"]["c"]) == 1_000_000
    assert len(FILES) >= 20 and len(XOSC) == 15


# ---- OpenSCENARIO and OpenDRIVE -----------------------------------------------------------


@pytest.fixture(scope="module")
def alks_copy() -> Iterator[Path]:
    """A writable copy of the ALKS set (the files refer to their catalogs and road)."""
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / "concrete_scenarios"
        shutil.copytree(ALKS, target)
        yield target


ATTRIBUTE_VALUES = st.one_of(
    st.sampled_from(["", "-1", "0", "1e308", "-1e308", "nan", "inf", "x", "$missing",
                     "${1/0}", "9" * 400, "true", "-0.0"]),
    st.text(max_size=12),
)


@st.composite
def xml_mutations(draw: st.DrawFn) -> tuple[str, int, str, str | None]:
    """(file kind, element index, attribute or '' for the element itself, new value or
    None: remove it)."""
    kind = draw(st.sampled_from(["xosc", "xodr"]))
    index = draw(st.integers(min_value=0, max_value=10_000))
    attribute = draw(st.sampled_from(["", "*"]))
    value = draw(st.none() | ATTRIBUTE_VALUES)
    return kind, index, attribute, value


def mutate_xml(tree: ET.ElementTree, index: int, attribute: str, value: str | None,
               huge: bool) -> None:
    """Change one element of `tree`: one of its attributes set or removed, or the element
    removed or duplicated (`huge`: 10,000 times)."""
    root = tree.getroot()
    parents = {child: parent for parent in root.iter() for child in parent}
    elements = [e for e in root.iter() if e is not root]
    element = elements[index % len(elements)]
    if attribute and element.attrib:
        name = sorted(element.attrib)[index % len(element.attrib)]
        if value is None:
            del element.attrib[name]
        else:
            element.attrib[name] = value
        return
    parent = parents[element]
    if value is None:
        parent.remove(element)
    else:
        for _ in range(10_000 if huge else 1):
            parent.append(copy.deepcopy(element))


def road_of(xosc: Path) -> Path | None:
    """The OpenDRIVE file an OpenSCENARIO file names (its `LogicFile`), if any."""
    text = xosc.read_text(encoding="utf-8")
    found = re.search(r'LogicFile filepath="([^"$]+)"', text)
    if found is None:  # given by a parameter: its default value
        found = re.search(r'ParameterDeclaration name="Road"[^>]*value="([^"]+)"', text)
    road = (xosc.parent / found.group(1)).resolve() if found else None
    return road if road is not None and road.is_file() else None


@FUZZ
@given(st.sampled_from(XOSC), xml_mutations(), st.booleans())
def test_a_mutated_openscenario_file_or_road_loads_or_gets_its_one_line_error(
        alks_copy: Path, xosc: Path, mutation: tuple[str, int, str, str | None],
        huge: bool) -> None:
    kind, index, attribute, value = mutation
    road = road_of(xosc)
    source = road if kind == "xodr" and road is not None else xosc
    target = alks_copy / source.relative_to(ALKS)
    tree = ET.parse(source)
    mutate_xml(tree, index, attribute, value, huge)
    try:
        tree.write(target, encoding="unicode")
        load_or_one_line_error(alks_copy / xosc.name, target, *(alks_copy / "catalogs").rglob("*"))
    finally:
        shutil.copyfile(source, target)
