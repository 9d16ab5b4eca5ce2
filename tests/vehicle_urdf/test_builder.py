"""The committed URDF is the builder's output, and its geometry is the ICCAS car's."""

from __future__ import annotations

import pytest

from vehicle_urdf import URDF_PATH, CarDimensions, build_urdf, read_geometry


def test_committed_urdf_equals_builder_output() -> None:
    assert URDF_PATH.read_text() == build_urdf(CarDimensions()), (
        "vehicle_urdf/car.urdf is stale: run `python -m vehicle_urdf`"
    )


def test_geometry_read_back_from_the_urdf() -> None:
    g = read_geometry()
    assert g.wheelbase == pytest.approx(2.7)
    assert g.body_length == pytest.approx(4.8)
    assert g.body_width == pytest.approx(1.6)
    assert g.mass == pytest.approx(1500.0, rel=0.02)
    assert g.front_axle == pytest.approx(1.35)
    assert 1.3 <= g.track <= 1.6
    d = CarDimensions()  # the sizes the committed URDF is built from
    assert g.tyre_width == pytest.approx(d.wheel_width)
    assert g.ground_clearance == pytest.approx(d.ground_clearance)
    assert g.body_height == pytest.approx(d.body_height)


def test_builder_follows_its_dimensions() -> None:
    g_text = build_urdf(CarDimensions(wheelbase=3.0))
    assert 'name="front_left_steer_joint" type="revolute"' in g_text
    assert g_text.count('type="continuous"') == 4
    assert "<origin xyz=\"1.5000 0.7000 0.0000\"" in g_text  # front axle at half of 3.0 m
