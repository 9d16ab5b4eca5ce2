"""The stopwatch sums spans per stage, an exception's span included."""

from __future__ import annotations

import time

import pytest

from world.core.stopwatch import Stopwatch


def test_spans_add_up_per_stage() -> None:
    watch = Stopwatch()
    for _ in range(3):
        with watch("a"):
            time.sleep(0.002)
    with watch("b"):
        pass
    assert watch.spans == {"a": 3, "b": 1}
    assert watch.seconds["a"] >= 0.006
    assert 0.0 <= watch.seconds["b"] < watch.seconds["a"]


def test_a_span_that_raises_is_counted() -> None:
    watch = Stopwatch()
    with pytest.raises(ValueError), watch("failing"):
        raise ValueError("boom")
    assert watch.spans == {"failing": 1}


def test_spans_from_elsewhere_are_added_under_a_prefix() -> None:
    watch = Stopwatch()
    watch.add("pose", 0.5)
    watch.add_all({"pose": 0.25, "sensor front": 1.0}, prefix="worker ")
    watch.add_all({"pose": 0.25}, prefix="worker ")
    assert watch.seconds == {"pose": 0.5, "worker pose": 0.5, "worker sensor front": 1.0}
    assert watch.spans == {"pose": 1, "worker pose": 2, "worker sensor front": 1}
