"""The environment's laws (`world.environment`) and what a camera makes of them
(`world.sensors.camera_weather`), on synthetic images: Koschmieder's fog, ITU-R P.1814's
rain, the twilight light, the auto-exposure's darkness and the noise it adds."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from world.environment import (
    CLEAR,
    KOSCHMIEDER,
    cloud_factor,
    fog_extinction,
    precipitation_extinction,
    sky_illuminance,
    solar_elevation,
    transmission,
)
from world.frames import CameraInfo, SensorMount
from world.sensors.camera_weather import (
    AIRLIGHT,
    FULL_EXPOSURE,
    MAX_GAIN,
    CameraWeather,
    exposure,
    noise_sigma,
)

INFO = CameraInfo("front", 64, 48, math.radians(80.0), SensorMount(0.0, 0.0, 1.5, 0, 0, 0))


def depth_buffer_at(distance_z: float) -> float:
    """The depth buffer's value of a point `distance_z` [m] along the optical axis (the
    inverse of the projection's linearisation)."""
    near, far = INFO.near, INFO.far
    return (far - far * near / distance_z) / (far - near)


def test_fog_leaves_two_percent_contrast_at_the_visual_range() -> None:
    for v in (30.0, 200.0, 1000.0):
        assert transmission(v, fog_extinction(v)) == pytest.approx(0.02)
    assert round(KOSCHMIEDER, 3) == 3.912
    assert CLEAR.extinction == 0.0 and math.isinf(CLEAR.visual_range)


def test_rain_extinction_follows_itu_r_p1814() -> None:
    # 1.076 R^0.67 dB/km: 25 mm/h (heavy rain) -> 9.3 dB/km -> 2.14 /km -> 1.83 km visual range
    alpha = precipitation_extinction(25.0)
    assert alpha == pytest.approx(1.076 * 25.0**0.67 / 4.3429 / 1000.0, rel=1e-4)
    assert KOSCHMIEDER / alpha == pytest.approx(1827.0, rel=0.001)
    assert precipitation_extinction(0.0) == 0.0
    assert precipitation_extinction(25.0, snow=True) > alpha  # snow hides more than rain
    both = replace(CLEAR, fog_visual_range=100.0, precipitation=25.0)
    assert both.extinction == pytest.approx(fog_extinction(100.0) + alpha)  # they add up


def test_light_follows_the_sun_through_twilight() -> None:
    assert sky_illuminance(math.radians(90.0)) == pytest.approx(1e5, rel=0.01)
    assert sky_illuminance(0.0) == pytest.approx(400.0, rel=0.01)  # sunset
    assert sky_illuminance(math.radians(-6.0)) == pytest.approx(3.4, rel=0.01)  # civil dusk
    assert sky_illuminance(math.radians(-30.0)) == pytest.approx(1e-3, rel=0.01)  # night
    assert cloud_factor(0.0) == 1.0 and cloud_factor(8.0) == pytest.approx(0.25)
    # equinox-ish noon at 48 deg N: the sun about 90 - 48 deg high; midnight: far below
    noon = 1584792000.0  # 2020-03-21T12:00:00Z
    assert math.degrees(solar_elevation(noon)) == pytest.approx(42.0, abs=1.0)
    assert math.degrees(solar_elevation(noon + 12 * 3600.0)) < -30.0


def test_auto_exposure_compensates_then_darkens() -> None:
    assert exposure(1e5) == exposure(FULL_EXPOSURE)
    assert exposure(FULL_EXPOSURE).gain == 1.0 and exposure(FULL_EXPOSURE).brightness == 1.0
    assert exposure(100.0).gain == pytest.approx(10.0)
    assert exposure(100.0).brightness == pytest.approx(1.0)  # the gain still makes it up
    low = FULL_EXPOSURE / MAX_GAIN
    assert exposure(low).brightness == pytest.approx(1.0)
    assert exposure(low / 10.0).gain == MAX_GAIN
    assert exposure(low / 10.0).brightness == pytest.approx(0.1)  # a decade less light
    assert exposure(0.0).brightness == 0.0
    assert noise_sigma(100.0, 1.0) == 0.0  # daylight: nothing added
    assert noise_sigma(100.0, 64.0) > noise_sigma(100.0, 8.0) > 0.0


def test_fog_per_pixel_from_the_depth_buffer() -> None:
    """A pixel whose ray meets a surface at the visual range keeps 2 % of its own light and
    takes 98 % of the airlight; the sky is airlight alone."""
    weather = CameraWeather(INFO)
    v = 40.0
    rgb = np.zeros((INFO.height, INFO.width, 3), dtype=np.uint8)  # black surfaces
    depth = np.full((INFO.height, INFO.width), depth_buffer_at(v), dtype=np.float32)
    depth[0, :] = 1.0  # the top row sees the sky
    out = weather.apply(rgb, depth, replace(CLEAR, fog_visual_range=v), (0,))
    centre = out[INFO.height // 2, INFO.width // 2].astype(float)  # on the axis: d = z
    np.testing.assert_allclose(centre, 0.98 * AIRLIGHT, atol=1.0)
    np.testing.assert_array_equal(out[0], np.broadcast_to(AIRLIGHT, (INFO.width, 3)))
    corner = out[-1, -1].astype(float)  # off axis: the ray is longer, more fog
    assert (corner >= centre).all()
    assert weather.distance(depth)[INFO.height // 2, INFO.width // 2] == pytest.approx(
        v, rel=1e-3)


def test_clear_daylight_is_untouched() -> None:
    weather = CameraWeather(INFO)
    rgb = np.random.default_rng(1).integers(0, 256, (INFO.height, INFO.width, 3), np.uint8)
    depth = np.full((INFO.height, INFO.width), 0.5, dtype=np.float32)
    assert weather.apply(rgb, depth, CLEAR, (0,)) is rgb
    assert weather.apply(rgb, depth, replace(CLEAR, illuminance=FULL_EXPOSURE), (0,)) is rgb


def test_night_lowers_the_lane_lines_contrast_against_the_noise() -> None:
    """Paint (200 DN) beside asphalt (80 DN): by day the two are 120 DN apart without noise;
    at 1 lx they are a few DN apart in noise of several DN."""
    weather = CameraWeather(INFO)
    rgb = np.full((INFO.height, INFO.width, 3), 80, dtype=np.uint8)
    rgb[:, : INFO.width // 2] = 200
    depth = np.full((INFO.height, INFO.width), 0.5, dtype=np.float32)

    def contrast_to_noise(illuminance: float) -> float:
        out = weather.apply(rgb, depth, replace(CLEAR, illuminance=illuminance), (7, 0, 1))
        paint, asphalt = out[:, : INFO.width // 2].astype(float), out[:, INFO.width // 2:]
        noise = max(float(asphalt.std()), 0.5)  # half a DN: the rounding's
        return float(paint.mean() - asphalt.mean()) / noise

    day, dusk, night = (contrast_to_noise(e) for e in (1e4, 30.0, 1.0))
    assert day > dusk > night
    assert night < 2.0  # the lines barely stand out of the noise


def test_noise_is_seeded() -> None:
    """Same seed, same bytes (a fresh camera model, as another process would have); another
    frame, other noise."""
    rgb = np.full((INFO.height, INFO.width, 3), 120, dtype=np.uint8)
    depth = np.full((INFO.height, INFO.width), 0.5, dtype=np.float32)
    env = replace(CLEAR, illuminance=5.0, fog_visual_range=80.0)
    a = CameraWeather(INFO).apply(rgb, depth, env, (3, 4, 0, 100_000))
    b = CameraWeather(INFO).apply(rgb, depth, env, (3, 4, 0, 100_000))
    c = CameraWeather(INFO).apply(rgb, depth, env, (3, 4, 0, 200_000))
    assert a.tobytes() == b.tobytes()
    assert a.tobytes() != c.tobytes()
