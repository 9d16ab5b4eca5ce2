"""The conventions every stage shares (`world.frames`): the one speed conversion and the one
angle wrap."""

from __future__ import annotations

import math

import pytest

from world.frames import MPS_PER_KPH, kph, to_kph, wrap_angle


def test_speed_conversion_is_named_and_exact() -> None:
    assert MPS_PER_KPH == 1000.0 / 3600.0
    assert kph(36.0) == pytest.approx(10.0)
    assert to_kph(kph(50.0)) == pytest.approx(50.0)
    assert kph(50.0) == 50.0 / 3.6  # the same bits as the old `/ 3.6`


@pytest.mark.parametrize(("angle", "wrapped"), [
    (0.0, 0.0), (0.3, 0.3), (-0.3, -0.3), (math.pi, math.pi), (-math.pi, math.pi),
    (3.0 * math.pi, math.pi), (2.0 * math.pi + 0.25, 0.25), (-2.0 * math.pi - 0.25, -0.25),
])
def test_wrap_angle_is_into_minus_pi_exclusive_pi_inclusive(angle: float,
                                                             wrapped: float) -> None:
    assert wrap_angle(angle) == pytest.approx(wrapped, abs=1e-12)
    assert -math.pi < wrap_angle(angle) <= math.pi


def test_wrap_angle_leaves_angles_inside_the_range_exactly_as_they_are() -> None:
    for angle in (0.1, -2.5, 3.1, -3.14159):
        assert wrap_angle(angle) == angle
