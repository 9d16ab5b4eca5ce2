"""Fuzzing the OpenDRIVE reader directly: mutated attributes and elements of the ALKS roads,
and random planView records; the outcome is a route or the one-line `OpenDriveError`, never
another exception."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.fuzzing import FUZZ, scaled
from tests.world.map.opendrive.roads import geometry_xml, road_xml
from world.map.opendrive import OpenDriveError, load_opendrive
from world.map.opendrive.model import Arc, Geometry, Line, ParamPoly3, Poly3Shape, Shape, Spiral
from world.map.opendrive.route import build_route

pytestmark = pytest.mark.fuzz

ALKS = sorted((Path(__file__).parents[4] / "tests/data/alks/logical_scenarios"
               / "concrete_scenarios/road_networks").glob("*.xodr"))
VALUES = ["0", "-1", "1e999", "NaN", "inf", "", "x", "1" * 5000, "-0.0", "1e-9", "1e9", "3.5",
          "0.5", "-1e300", "2", "1e4"]


def outcome(path: Path) -> None:
    """A route, or the one-line refusal naming the file."""
    try:
        build_route(load_opendrive(path))
    except OpenDriveError as e:
        message = str(e)
        assert "\n" not in message and message.startswith(str(path))


@st.composite
def mutated(draw: st.DrawFn) -> tuple[int, str]:
    """(which ALKS road, its text with one attribute set or one element duplicated or
    removed)."""
    k = draw(st.integers(0, len(ALKS) - 1))
    root = ET.parse(ALKS[k]).getroot()
    elements = [e for e in root.iter() if e is not root]
    element = elements[draw(st.integers(0, len(elements) - 1))]
    parent = next(p for p in root.iter() if element in list(p))
    kind = draw(st.sampled_from(["attribute", "duplicate", "remove"]))
    if kind == "attribute" and element.attrib:
        name = draw(st.sampled_from(sorted(element.attrib)))
        element.set(name, draw(st.sampled_from(VALUES) | st.floats().map(repr)))
    elif kind == "duplicate":
        parent.insert(list(parent).index(element), ET.fromstring(ET.tostring(element)))
    else:
        parent.remove(element)
    return k, ET.tostring(root, encoding="unicode")


@FUZZ
@given(mutated())
def test_a_mutated_alks_road_gives_a_route_or_the_one_line_refusal(
        tmp_path_factory: pytest.TempPathFactory, case: tuple[int, str]) -> None:
    path = tmp_path_factory.mktemp("fuzz") / ALKS[case[0]].name
    path.write_text(case[1], encoding="utf-8")
    outcome(path)


NUMBER = st.floats(allow_nan=True, allow_infinity=True) | st.floats(-2.0, 2.0)
SHAPES: st.SearchStrategy[Shape] = st.one_of(
    st.just(Line()), st.builds(Arc, NUMBER), st.builds(Spiral, NUMBER, NUMBER),
    st.builds(Poly3Shape, NUMBER, NUMBER, NUMBER, NUMBER),
    st.builds(ParamPoly3, NUMBER, NUMBER, NUMBER, NUMBER, NUMBER, NUMBER, NUMBER, NUMBER,
              st.sampled_from(["arcLength", "normalized"])))


def shape_xml(shape: Shape) -> str:
    if isinstance(shape, Poly3Shape):
        return f'<poly3 a="{shape.a!r}" b="{shape.b!r}" c="{shape.c!r}" d="{shape.d!r}"/>'
    if isinstance(shape, ParamPoly3):
        names = [f"{c}{uv}" for uv in "UV" for c in "abcd"]
        values = [shape.au, shape.bu, shape.cu, shape.du, shape.av, shape.bv, shape.cv,
                  shape.dv]
        attrs = " ".join(f'{n}="{v!r}"' for n, v in zip(names, values, strict=True))
        return f'<paramPoly3 {attrs} pRange="{shape.p_range}"/>'
    return ""


@scaled(50)
@given(st.lists(st.tuples(SHAPES, st.floats(-1.0, 300.0), st.floats(-1.0, 1.0)),
                min_size=1, max_size=6))
def test_random_geometry_records_give_a_route_or_the_one_line_refusal(
        tmp_path_factory: pytest.TempPathFactory,
        records: list[tuple[Shape, float, float]]) -> None:
    geoms, s, x = [], 0.0, 0.0
    for shape, length, hdg in records:
        geoms.append(geometry_xml(Geometry(s, x, 0.0, hdg, length, shape),
                                  shape_xml(shape) or None))
        s, x = s + length, x + length
    path = tmp_path_factory.mktemp("fuzz") / "road.xodr"
    path.write_text(road_xml("".join(geoms), s), encoding="utf-8")
    outcome(path)
