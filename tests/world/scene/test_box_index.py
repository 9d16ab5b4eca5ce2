"""The buildings' spatial index (`world.scene.box_index`): the same answers as comparing every
pair, and a town at its documented bounds laid out with work linear in its buildings."""

from __future__ import annotations

import numpy as np
import pytest

from avsim.scenario.bounds import MAX_BLOCK, MAX_TOWN_BLOCKS, MAX_TOWN_LANES
from world.map.town import TownLayout
from world.scene import town_scene
from world.scene.box_index import BoxIndex, Rect
from world.scene.town_scene import layout_town_buildings
from world.spec import TownSpec

GAP = 1.5  # [m]


def _brute_clear(a: Rect, placed: list[Rect]) -> bool:
    g = GAP
    return all(not (a[0] < b[2] + g and b[0] < a[2] + g and a[1] < b[3] + g and b[1] < a[3] + g)
               for b in placed)


@pytest.mark.parametrize("cell", [0.7, 5.0, 50.0])
def test_the_index_answers_as_every_pair_would(cell: float) -> None:
    rng = np.random.default_rng(3)
    index, placed = BoxIndex(GAP, cell), list[Rect]()
    for _ in range(2000):
        x, y = rng.uniform(-60.0, 60.0, 2)
        w, h = rng.uniform(0.1, 12.0, 2)
        rect = (float(x), float(y), float(x + w), float(y + h))
        clear = index.clear(rect)
        assert clear == _brute_clear(rect, placed)
        if clear:
            index.add(rect)
            placed.append(rect)
    assert len(placed) > 50  # the test placed boxes and refused others


def test_a_gap_exactly_kept_is_clear() -> None:
    index = BoxIndex(GAP, 10.0)
    index.add((0.0, 0.0, 10.0, 10.0))
    assert index.clear((10.0 + GAP, 0.0, 20.0, 10.0))
    assert not index.clear((10.0 + GAP - 1e-9, 0.0, 20.0, 10.0))
    assert index.clear((-20.0, 10.0 + GAP, -10.0 - GAP, 20.0))  # diagonal, gap on both axes


def test_a_town_at_its_bounds_lays_out_its_buildings_in_linear_work(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The largest town a file may ask for: each new building is compared with the few
    near it, not with every one placed (that was 18 million comparisons here)."""
    made: list[BoxIndex] = []

    class Counted(BoxIndex):
        def __init__(self, gap: float, cell: float) -> None:
            super().__init__(gap, cell)
            made.append(self)

    monkeypatch.setattr(town_scene, "BoxIndex", Counted)
    spec = TownSpec(MAX_TOWN_BLOCKS, MAX_TOWN_BLOCKS, MAX_BLOCK, MAX_TOWN_LANES, 3.5, 13.9,
                    "mixed")
    boxes = layout_town_buildings(TownLayout(spec), np.random.default_rng(1))
    assert len(boxes) > 5000  # every block's four sides are built up
    assert len(made) == 1
    assert made[0].compared < 10 * len(boxes)
