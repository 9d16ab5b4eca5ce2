"""The criteria's messages say what their values say: the same quantity, its sign kept, and
no rounding that shows a value on the wrong side of its threshold (`avsim.criteria.wording`)."""

from __future__ import annotations

import re

import pytest

from avsim.criteria.lane import LINE_HALF_WIDTH, TyresInLane
from avsim.criteria.wording import beside, signed
from tests.avsim.criteria.test_criteria_situations import ROAD, TRACK, TYRE, truth
from tests.roads import W


@pytest.mark.parametrize(("x", "text"), [
    (-0.32, "-0.32"), (0.32, "+0.32"), (-0.004, "-0.004"), (0.0004, "+0.0004"),
    (0.0, "+0.00"), (-1e-9, "-0.000000"),
])
def test_signed_keeps_the_sign_and_a_non_zero_digit(x: float, text: str) -> None:
    assert signed(x) == text


@pytest.mark.parametrize(("x", "ref", "digits", "text"), [
    (3.504, 3.5, 2, "3.504"), (3.6, 3.5, 1, "3.6"), (0.96, 1.0, 1, "0.96"),
    (0.04, 0.0, 1, "0.04"), (12.0, 12.0, 1, "12.0"), (2.0, 3.0, 1, "2.0"),
])
def test_beside_never_shows_a_value_equal_to_its_threshold(x: float, ref: float, digits: int,
                                                           text: str) -> None:
    assert beside(x, ref, digits) == text


def _margin_in(message: str) -> float:
    found = re.search(r"margin inside the lanes ([+-][0-9.]+) m", message)
    assert found is not None, message
    return float(found.group(1))


@pytest.mark.parametrize("over", [0.003, 0.32])  # [m] a tyre over lane 1's left line
def test_tyres_in_lane_message_states_the_margin_with_its_sign(over: float) -> None:
    """The value is the least margin inside the lines (negative: over them); the message of
    the first sample over gives that sample's margin, signed, never "0.00 m outside"."""
    c = TyresInLane(ROAD, TYRE)
    d = W + W / 2 - LINE_HALF_WIDTH - TRACK - TYRE + over  # the left tyres' edge `over` out
    c.update(truth(0.0, d))
    (infraction,) = c.take_infractions()
    value = c.result().value
    assert value == pytest.approx(-over)
    assert _margin_in(infraction.message) == pytest.approx(value, abs=5e-4)
    assert "negative: over" in infraction.message
