"""The GNSS receiver model (`world.sensors.gnss`): the wandering bias's statistics measured
on a long seeded sample, the white noise, outages, heading from motion, determinism, and
the presets' figures."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from world.ego.body import EgoTruth
from world.frames import GnssFix
from world.sensors.gnss import GnssSensor
from world.spec import GNSS_PRESETS, GnssSpec

DT = 0.1  # [s] the GNSS period (10 Hz)
CEP_PER_SIGMA = 1.1774  # CEP (50 %) of a circular Gaussian over its per-axis sigma


def truth(x: float = 10.0, y: float = -4.0, yaw: float = 0.5, speed: float = 14.0) -> EgoTruth:
    c, s = math.cos(yaw), math.sin(yaw)
    return EgoTruth(
        position=np.array([x, y, 0.5]), quaternion=np.array([0.0, 0.0, math.sin(yaw / 2),
                                                              math.cos(yaw / 2)]),
        rotation=np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), yaw=yaw,
        velocity=np.array([speed * c, speed * s, 0.0]), speed=speed, yaw_rate=0.0,
        wheel_spin=np.zeros(4), steering_angle=0.0)


def sample(spec: GnssSpec, seconds: float, seed: int = 11,
           ego: EgoTruth | None = None) -> tuple[list[GnssFix], np.ndarray]:
    """The fixes of `seconds` at 10 Hz and the wandering bias (N, 2) after each."""
    sensor = GnssSensor(spec, np.random.default_rng(seed))
    ego = ego if ego is not None else truth()
    fixes, wander = [], []
    for k in range(round(seconds / DT)):
        fixes.append(sensor.measure(k * DT, ego))
        wander.append(sensor.wander.copy())
    return fixes, np.array(wander)


FAST_TAU = 6.0  # [s] the consumer's bias, ten times faster: as many correlation times in
#   an hour as in ten, for the same process


@pytest.fixture(scope="module")
def long_consumer() -> tuple[list[GnssFix], np.ndarray]:
    """An hour of the consumer receiver, its bias ten times faster, without outages."""
    return sample(replace(GNSS_PRESETS["consumer"], dropout_rate=0.0, bias_tau=FAST_TAU),
                  3600.0)


def test_wandering_bias_has_the_stationary_sigma(
        long_consumer: tuple[list[GnssFix], np.ndarray]) -> None:
    _, wander = long_consumer
    spec = GNSS_PRESETS["consumer"]
    # 3600 s / (2 x 6 s) = 300 independent stretches: ~4 % standard error of the sigma
    for axis in (0, 1):
        assert np.std(wander[:, axis]) == pytest.approx(spec.bias_sigma, rel=0.12)
        assert abs(np.mean(wander[:, axis])) < 0.25 * spec.bias_sigma


def test_wandering_bias_has_the_correlation_time(
        long_consumer: tuple[list[GnssFix], np.ndarray]) -> None:
    _, wander = long_consumer
    tau = FAST_TAU
    for axis in (0, 1):
        b = wander[:, axis] - np.mean(wander[:, axis])
        a = float(np.dot(b[:-1], b[1:]) / np.dot(b[:-1], b[:-1]))  # lag-one coefficient
        assert -DT / math.log(a) == pytest.approx(tau, rel=0.15)
        lag = round(tau / DT)  # the autocorrelation one correlation time apart: 1/e
        rho = float(np.dot(b[:-lag], b[lag:]) / np.dot(b, b) * len(b) / (len(b) - lag))
        assert rho == pytest.approx(math.exp(-1.0), abs=0.1)


def test_fix_is_truth_plus_bias_plus_white_noise(
        long_consumer: tuple[list[GnssFix], np.ndarray]) -> None:
    fixes, wander = long_consumer
    ego = truth()
    spec = GNSS_PRESETS["consumer"]
    white = np.array([[f.x - ego.position[0], f.y - ego.position[1]] for f in fixes]) - wander
    assert np.std(white, axis=0) == pytest.approx([spec.sigma, spec.sigma], rel=0.03)
    lag_one = float(np.corrcoef(white[:-1, 0], white[1:, 0])[0, 1])
    assert abs(lag_one) < 0.02  # white
    assert all(f.sigma == pytest.approx(math.hypot(spec.sigma, spec.bias_sigma))
               for f in fixes[:10])


def test_constant_bias_adds_to_the_wander() -> None:
    spec = replace(GNSS_PRESETS["rtk"], bias=(1.5, -1.0))
    fixes, _ = sample(spec, 200.0)
    ego = truth()
    err = np.array([[f.x - ego.position[0], f.y - ego.position[1]] for f in fixes])
    assert np.mean(err, axis=0) == pytest.approx([1.5, -1.0], abs=0.02)
    assert all(f.sigma == 0.05 for f in fixes)  # the receiver does not know of it


def test_outages_flag_the_fix_invalid_at_the_set_rate_and_length() -> None:
    spec = replace(GNSS_PRESETS["rtk"], dropout_rate=1.0 / 2.0, dropout_duration=0.5)
    fixes, _ = sample(spec, 2000.0)
    valid = np.array([f.valid for f in fixes])
    starts = np.flatnonzero(valid[:-1] & ~valid[1:])
    ends = np.flatnonzero(~valid[:-1] & valid[1:])
    lengths = (ends[: len(starts)] - starts[: len(ends)]) * DT if ends[0] > starts[0] \
        else (ends[1:len(starts) + 1] - starts[: len(ends) - 1]) * DT
    # 2000 s / (2 + 0.5) s: ~800 outages; exponential lengths, sampled every 0.1 s
    assert len(starts) == pytest.approx(2000.0 / 2.5, rel=0.1)
    assert float(np.mean(lengths)) == pytest.approx(0.5 + DT / 2, rel=0.1)
    assert 1.0 - valid.mean() == pytest.approx(0.5 / 2.5, rel=0.1)
    bad = [f for f in fixes if not f.valid]
    assert all(math.isnan(f.x) and math.isnan(f.y) and math.isnan(f.heading) for f in bad)


def test_heading_from_motion_has_none_at_a_standstill() -> None:
    spec = GNSS_PRESETS["consumer"]
    sensor = GnssSensor(spec, np.random.default_rng(0))
    assert sensor.heading_sigma(0.0) == pytest.approx(math.hypot(spec.heading_sigma,
                                                                 math.pi / 2))
    # the data sheets' 0.3 deg (50 %) at 30 m/s: a median of |error| of 0.6745 sigma
    assert 0.6745 * math.degrees(sensor.heading_sigma(30.0)) == pytest.approx(0.3, abs=0.05)
    fixes, _ = sample(spec, 100.0, ego=truth(speed=30.0, yaw=3.1))
    err = np.array([math.remainder(f.heading - 3.1, math.tau) for f in fixes if f.valid])
    assert float(np.std(err)) == pytest.approx(sensor.heading_sigma(30.0), rel=0.15)
    rtk = GnssSensor(GNSS_PRESETS["rtk"], np.random.default_rng(0))
    assert rtk.heading_sigma(0.0) == GNSS_PRESETS["rtk"].heading_sigma  # two antennas


def test_same_seed_same_fixes_other_seed_others() -> None:
    a, _ = sample(GNSS_PRESETS["degraded"], 300.0, seed=5)
    b, _ = sample(GNSS_PRESETS["degraded"], 300.0, seed=5)
    c, _ = sample(GNSS_PRESETS["degraded"], 300.0, seed=6)
    assert repr(a) == repr(b)  # bit for bit (NaN != NaN, so compare the text)
    assert repr(a) != repr(c)


def test_rtk_draws_exactly_the_white_noise_model() -> None:
    """Without wander or outages, the fixes are those of the model before presets: three
    normals per fix, truth + bias + sigma x noise."""
    spec = replace(GNSS_PRESETS["rtk"], bias=(0.3, -0.2))
    fixes, _ = sample(spec, 10.0, seed=3)
    rng = np.random.default_rng(3)
    ego = truth()
    for f in fixes:
        n = rng.normal(0.0, 1.0, 3)
        assert (f.x, f.y) == (float(ego.position[0] + 0.3 + 0.05 * n[0]),
                              float(ego.position[1] - 0.2 + 0.05 * n[1]))
        assert f.heading == pytest.approx(ego.yaw + spec.heading_sigma * n[2], abs=1e-12)


def test_presets() -> None:
    rtk, consumer, degraded = (GNSS_PRESETS[n] for n in ("rtk", "consumer", "degraded"))
    assert GnssSpec() == consumer  # the default
    # rtk: what a `gnss:` block meant before the presets
    assert (rtk.sigma, rtk.bias, rtk.bias_sigma, rtk.dropout_rate) == (0.05, (0.0, 0.0), 0.0, 0.0)
    assert rtk.heading_sigma == pytest.approx(math.radians(0.2))
    # consumer: ~1 m wandering bias, 60 s; its CEP no better than the data sheets' open-sky
    # figures (ZED-F9P 1.5 m, NEO-M8 2.0-2.5 m)
    assert (consumer.bias_sigma, consumer.bias_tau) == (1.2, 60.0)
    assert CEP_PER_SIGMA * consumer.stated_sigma == pytest.approx(1.46, abs=0.01)
    assert consumer.dropout_rate > 0.0 and consumer.velocity_sigma > 0.0
    # degraded: worse than consumer in every figure
    for knob in ("sigma", "heading_sigma", "bias_sigma", "velocity_sigma", "dropout_rate",
                 "dropout_duration"):
        assert getattr(degraded, knob) > getattr(consumer, knob), knob
    assert degraded.bias_tau < consumer.bias_tau
